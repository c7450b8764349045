import logging
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest
from geometry_msgs.msg import PoseStamped
from harness import SENSOR_QOS, ros_env, start_process, stop_with
from rclpy.qos import DurabilityPolicy, QoSProfile
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import Image
from std_msgs.msg import Float64

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.core.bagio import BagReader, BagWriter
from lumpbeam_ros.nodes import player as player_module
from lumpbeam_ros.nodes.player import Player

T0 = 1000.0


@pytest.fixture
def short_bag(tmp_path):
    with BagWriter(tmp_path / 'short') as bag:
        for i in range(60):  # 0.5 s at 120 Hz
            bag.write_pose('/tip_pose', T0 + i / 120, 2.3, -0.001 * i, 0.0)
            if i % 20 == 0:
                bag.write_image('/camera/image_raw', T0 + i / 120, np.full((4, 6), i, np.uint8))
        bag.write_float('/tip_load', T0, 4.5)
    return tmp_path / 'short'


def _play(ros_graph, bag, **kwargs):
    """Plays in a thread (as the CLI does in its own process) while the test's graph spins."""
    player = Player(BagReader(bag), context=ros_graph.context, **kwargs)
    ros_graph.spin_for(0.5)  # discovery
    result = {}
    thread = threading.Thread(target=lambda: result.update(stats=player.play()))
    thread.start()
    ros_graph.spin_until(lambda: not thread.is_alive(), 10.0)
    thread.join()
    return player, result['stats']


def test_replay_keeps_content_timing_and_clock(ros_graph, short_bag):
    poses = ros_graph.collect('/tip_pose', PoseStamped, 100)
    images = ros_graph.collect('/camera/image_raw', Image, SENSOR_QOS)
    clock = ros_graph.collect('/clock', Clock, 100)
    # When the player wrote each pose (the middleware's source stamp, wall clock, ns): this
    # test's own executor may run the callbacks late and in bursts on a loaded machine.
    sent_ns = []
    ros_graph.node.create_subscription(
        PoseStamped, '/tip_pose', lambda m, info: sent_ns.append(info['source_timestamp']), 100
    )
    started_ns = time.time_ns()
    _, stats = _play(ros_graph, short_bag)
    assert ros_graph.spin_until(lambda: len(poses) == 60 and len(sent_ns) == 60, 5.0)
    assert stats.published == {'/camera/image_raw': 3, '/tip_load': 1, '/tip_pose': 60}
    np.testing.assert_allclose([p.pose.position.z for p in poses], -0.001 * np.arange(60))
    assert [bytes(m.data)[0] for m in images] == [0, 20, 40]
    ticks = [c.clock.sec + c.clock.nanosec * 1e-9 for c in clock]
    assert len(ticks) == 64 and ticks[0] == T0 and np.all(np.diff(ticks) >= 0)
    _assert_paced(sent_ns, stats, 59 / 120)
    assert sent_ns[0] > started_ns


def _assert_paced(sent_ns, stats, span_s):
    """The poses went out on their schedule, give or take the player's own lateness.

    The last pose is due ``span_s`` after the first was due, and each was sent no earlier
    than due and at most the largest lateness after. How late is a matter of the machine's
    load, measured by `lumpbeam bench` (play_timing_p99), not here.
    """
    lateness = max(stats.lateness_s)
    assert min(stats.lateness_s) >= 0.0
    sent_span = (sent_ns[-1] - sent_ns[0]) * 1e-9
    assert span_s - lateness - 1e-3 <= sent_span <= span_s + lateness + 1e-3


def test_rate_scales_the_timing(ros_graph, short_bag):
    sent_ns = []
    ros_graph.node.create_subscription(
        PoseStamped, '/tip_pose', lambda m, info: sent_ns.append(info['source_timestamp']), 100
    )
    _, stats = _play(ros_graph, short_bag, rate=4.0, topics=['/tip_pose'])
    assert stats.published == {'/tip_pose': 60}
    assert ros_graph.spin_until(lambda: len(sent_ns) == 60, 5.0)
    _assert_paced(sent_ns, stats, 59 / 120 / 4.0)


def test_tip_load_is_latched_for_late_subscribers(ros_graph, short_bag):
    player, _ = _play(ros_graph, short_bag, topics=['/tip_load'])  # kept alive: it latches
    latched = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
    late = ros_graph.collect('/tip_load', Float64, latched)
    assert ros_graph.spin_until(lambda: len(late) == 1, 5.0)
    assert late[0].data == 4.5
    player.destroy_node()


def test_a_truncated_bag_plays_what_is_readable(ros_graph, tmp_path, caplog):
    with BagWriter(tmp_path / 'cut') as bag:
        for i in range(40):
            bag.write_float('/tip_load', T0 + i / 100, float(i))
            if i == 19:
                bag.flush()
                flushed_size = os.path.getsize(tmp_path / 'cut' / 'cut.mcap')
    data = (tmp_path / 'cut' / 'cut.mcap').read_bytes()
    (tmp_path / 'cut' / 'cut.mcap').write_bytes(data[: flushed_size + 30])  # a kill mid-chunk
    with caplog.at_level(logging.WARNING):
        _, stats = _play(ros_graph, tmp_path / 'cut')
    assert stats.published == {'/tip_load': 20}
    assert 'no closing index' in caplog.text


@pytest.mark.parametrize(
    ('argv', 'match'),
    [
        (['play', '{bag}', '--topics', '/nope'], 'no topic /nope'),
        (['play', '{custom}'], 'message type my_pkg/msg/Thing is not installed'),
        (['play', '{missing}'], 'no such bag'),
        (
            ['play', '{bag}', '--namespace', 'beam_a'],
            "lumpbeam play: error: --namespace 'beam_a': namespace must be absolute",
        ),
        (
            ['play', '{missing}', '--namespace', '/beam a'],
            "--namespace '/beam a': namespace must not contain characters other than",
        ),
    ],
)
def test_bad_invocations_print_one_line(tmp_path, short_bag, capsys, argv, match):
    with BagWriter(tmp_path / 'custom') as bag:
        bag.add_topic('/custom', 'my_pkg/msg/Thing', msgdef='float64 value', type_hash='RIHS01_0')
    paths = {'bag': short_bag, 'custom': tmp_path / 'custom', 'missing': tmp_path / 'missing'}
    assert main([a.format(**paths) for a in argv]) == 2
    err = capsys.readouterr().err.strip()
    assert match in err and '\n' not in err


def test_play_command_end_to_end(short_bag, capsys, monkeypatch, ros_domain_id):
    monkeypatch.setenv('ROS_DOMAIN_ID', str(ros_domain_id))
    assert main(['play', str(short_bag), '--rate', '5', '--delay', '0.1']) == 0
    out = capsys.readouterr().out
    assert 'played' in out and '64 messages' in out


def test_play_command_in_a_namespace(ros_graph, short_bag):
    spaced = ros_graph.collect('/beam_a/tip_pose', PoseStamped, 100)
    unspaced = ros_graph.collect('/tip_pose', PoseStamped, 100)
    clock = ros_graph.collect('/clock', Clock, 100)
    argv = ['play', str(short_bag), '--topics', '/tip_pose', '--namespace', '/beam_a']
    proc = subprocess.Popen(
        [sys.executable, '-m', 'lumpbeam_ros.apps.cli.main', *argv, '--delay', '3.0'],
        env=ros_env(ros_graph.domain_id),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        ok = ros_graph.spin_until(lambda: len(spaced) == 60, 30.0)
    finally:
        stdout, stderr = proc.communicate(timeout=30)
    assert ok, (len(spaced), stdout, stderr)
    assert proc.returncode == 0, stderr
    assert '(1 pass): 60 messages in the last pass' in stdout
    assert ros_graph.spin_until(lambda: len(clock) == 60, 5.0)  # /clock stays graph-wide
    assert unspaced == []


def test_player_waits_for_subscribers_and_for_delivery(ros_graph, short_bag):
    player = Player(BagReader(short_bag), ['/tip_pose'], context=ros_graph.context)
    assert player.wait_for_subscribers(0.2) == ['/tip_pose']  # nobody listens yet
    poses = ros_graph.collect('/tip_pose', PoseStamped, 100)
    waiter = threading.Thread(target=lambda: player.wait_for_subscribers(5.0))
    waiter.start()
    ros_graph.spin_until(lambda: not waiter.is_alive(), 5.0)
    assert player.wait_for_subscribers(0.0) == []
    _, stats = _play(ros_graph, short_bag)
    assert stats.delivered
    assert ros_graph.spin_until(lambda: len(poses) == 60, 5.0)


def _out_of_order_bag(path):
    """A bag whose messages were written out of log-time order (rosbags' writer keeps it)."""
    from rosbags.rosbag2 import StoragePlugin, Writer

    from lumpbeam_ros.core.bagio import convert
    from lumpbeam_ros.core.bagio.typestore import serialize, type_description

    msgdef, rihs01 = type_description('geometry_msgs/msg/PoseStamped')
    with Writer(path, version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        connection = writer.add_connection(
            '/tip_pose', 'geometry_msgs/msg/PoseStamped', msgdef=msgdef, rihs01=rihs01
        )
        for i in [5, 1, 4, 2, 3, 0, 9, 7, 8, 6]:
            ns = convert.seconds_to_ns(T0 + i / 100)
            pose = convert.pose_stamped(ns, 2.3, -0.001 * i, 0.0, 'beam_base')
            writer.write(connection, ns, serialize(pose))
    return path


@pytest.mark.parametrize('cut', [False, True])
def test_a_bag_out_of_order_plays_every_message_with_a_monotonic_clock(ros_graph, tmp_path, cut):
    bag = _out_of_order_bag(tmp_path / 'shuffled')
    if cut:  # without its summary the file is read in the order it was written
        data_file = next(bag.glob('*.mcap'))
        data_file.write_bytes(data_file.read_bytes()[:-200])
    poses = ros_graph.collect('/tip_pose', PoseStamped, 100)
    clock = ros_graph.collect('/clock', Clock, 100)
    _, stats = _play(ros_graph, bag)
    assert ros_graph.spin_until(lambda: len(poses) == 10 and len(clock) == 10, 5.0)
    ticks = [c.clock.sec * 10**9 + c.clock.nanosec for c in clock]
    assert np.all(np.diff(ticks) >= 0)
    z = sorted(round(-p.pose.position.z * 1000) for p in poses)
    assert z == list(range(10))
    assert (stats.out_of_order > 0) == cut


def test_a_namespaced_player_and_recorder_keep_the_bag_names(ros_graph, short_bag, tmp_path):
    from lumpbeam_ros.nodes.recorder import Recorder

    spaced = ros_graph.collect('/beam_a/tip_pose', PoseStamped, 100)
    unspaced = ros_graph.collect('/tip_pose', PoseStamped, 100)
    clock = ros_graph.collect('/clock', Clock, 100)
    # A beam outside the namespace: its topic is not the namespaced recorder's.
    ros_graph.publish('/tip_load', Float64(data=1.0), 10)
    bag = BagWriter(tmp_path / 'again')
    recorder = Recorder(
        bag, ['/tip_pose', '/tip_load', '/clock'], context=ros_graph.context, namespace='/beam_a'
    )
    ros_graph.add_node(recorder)
    player = Player(
        BagReader(short_bag),
        ['/tip_pose', '/tip_load'],
        context=ros_graph.context,
        namespace='/beam_a',
    )
    assert ros_graph.spin_until(lambda: not recorder.missing(), 10.0)
    outlet = player._outlets['/tip_pose']
    assert ros_graph.spin_until(lambda: outlet.get_subscription_count() >= 2)
    ros_graph.spin_for(0.3)  # the subscriptions settle on the publishers
    result = {}
    thread = threading.Thread(target=lambda: result.update(stats=player.play()))
    thread.start()
    ros_graph.spin_until(lambda: not thread.is_alive(), 10.0)
    thread.join()
    stats = result['stats']
    assert stats.published == {'/tip_load': 1, '/tip_pose': 60}
    assert ros_graph.spin_until(lambda: len(spaced) == 60, 5.0)
    assert ros_graph.spin_until(lambda: len(clock) == 61, 5.0)  # /clock is graph-wide
    assert unspaced == []
    assert recorder.bag_topic('/beam_a/tip_pose') == '/tip_pose'
    assert recorder.bag_topic('/beam_b/tip_pose') is None
    assert recorder.bag_topic('/clock') == '/clock'
    assert ros_graph.spin_until(lambda: recorder.received.get('/tip_pose') == 60, 5.0)
    bag.close()
    reader = BagReader(tmp_path / 'again')
    assert set(reader.topics) == {'/tip_pose', '/tip_load', '/clock'}
    loads = [m.data for _, m in reader.messages('/tip_load', 'std_msgs/msg/Float64')]
    assert loads == [4.5]  # the namespace's load, not the other beam's 1.0


@pytest.fixture
def gap_bag(tmp_path):
    """Five poses, a jump of 1e6 s (11.6 days), five more."""
    with BagWriter(tmp_path / 'gap') as bag:
        for i in range(10):
            bag.write_pose('/tip_pose', T0 + (1e6 if i >= 5 else 0.0) + i / 100, 2.3, -i, 0.0)
    return tmp_path / 'gap'


def test_a_huge_gap_is_played_short_and_counted(ros_graph, gap_bag, monkeypatch):
    monkeypatch.setattr(player_module, 'MAX_GAP_S', 0.3)
    poses = ros_graph.collect('/tip_pose', PoseStamped, 100)
    clock = ros_graph.collect('/clock', Clock, 100)
    _, stats = _play(ros_graph, gap_bag)
    assert stats.published == {'/tip_pose': 10} and not stats.stopped
    assert stats.gaps_shortened == 1
    assert stats.longest_gap_s == pytest.approx(1e6 + 0.01, abs=1e-3)
    assert ros_graph.spin_until(lambda: len(poses) == 10 and len(clock) == 10, 5.0)
    # /clock keeps the bag's time: it jumps by the gap.
    ticks = np.array([c.clock.sec + c.clock.nanosec * 1e-9 for c in clock])
    assert ticks[5] - ticks[4] == pytest.approx(1e6 + 0.01, abs=1e-3)


@pytest.mark.parametrize('sig', [signal.SIGINT, signal.SIGTERM])
def test_play_stops_within_the_bound_of_a_signal_in_a_huge_gap(ros_graph, gap_bag, sig):
    poses = ros_graph.collect('/tip_pose', PoseStamped, 100)
    argv = ['lumpbeam_ros.apps.cli.main', 'play', str(gap_bag), '--delay', '3.0']
    process = start_process(ros_env(ros_graph.domain_id), *argv)
    try:
        ok = ros_graph.spin_until(lambda: len(poses) == 5, 30.0)
    finally:
        code, stdout, stderr = stop_with(process, sig)
    assert ok, stderr
    assert code == 0, stderr
    assert 'played' in stdout and '5 messages in the last pass' in stdout
