import signal
import subprocess
import sys
import time

import numpy as np
import pytest
from geometry_msgs.msg import PoseStamped
from harness import ros_env
from mcap.reader import make_reader
from rosbags.highlevel import AnyReader
from std_msgs.msg import Float64

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.core.bagio import BagReader, read_load_events, read_tip_poses


def _start_recorder(ros_graph, out, *extra):
    cmd = [sys.executable, '-m', 'lumpbeam_ros.apps.cli.main', 'record', str(out), *extra]
    return subprocess.Popen(
        cmd,
        env=ros_env(ros_graph.domain_id),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


def _publish_poses(ros_graph, n, rate_hz=200.0, topic='/tip_pose'):
    msg = PoseStamped()
    msg.header.frame_id = 'beam_base'
    ros_graph.publish(topic, msg)  # creates the publisher
    assert ros_graph.wait_for_subscribers(topic, timeout=15.0)
    ros_graph.spin_for(0.3)  # the recorder's subscription settles on the new publisher
    for i in range(n):
        msg.header.stamp.sec, msg.header.stamp.nanosec = 100 + i, 0
        msg.pose.position.z = -0.001 * i
        ros_graph.publish(topic, msg)
        time.sleep(1.0 / rate_hz)


def test_sigkill_keeps_everything_before_the_last_flush_and_repair_makes_it_whole(
    ros_graph, tmp_path, mcap_doctor, capsys
):
    out = tmp_path / 'killed'
    proc = _start_recorder(ros_graph, out, '/tip_pose', '--flush-period', '0.2')
    try:
        _publish_poses(ros_graph, 200)
        time.sleep(0.6)  # > flush period: every pose is on disk
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait(10)
    reader = BagReader(out)
    assert reader.truncated  # no summary: the process never closed the file
    poses = read_tip_poses(reader)
    stamps = poses.t[poses.t >= 100]
    np.testing.assert_array_equal(stamps, 100.0 + np.arange(200))
    np.testing.assert_allclose(poses.z[poses.t >= 100], -0.001 * np.arange(200))
    # Other readers need the closing summary the killed writer never wrote.
    with pytest.raises(Exception, match='magic'):
        with AnyReader([out]) as bag:
            list(bag.messages())
    assert main(['repair', str(out)]) == 0
    repaired = tmp_path / 'killed-repaired'
    assert f'into {repaired}: {poses.t.size} messages' in capsys.readouterr().out
    assert not BagReader(repaired).truncated
    assert BagReader(repaired).topics['/tip_pose'].count == poses.t.size
    np.testing.assert_array_equal(read_tip_poses(repaired).t, poses.t)
    with AnyReader([repaired]) as bag:  # rosbags, an independent reader
        got = [bag.deserialize(raw, c.msgtype) for c, _, raw in bag.messages()]
    assert [m.header.stamp.sec for m in got if m.header.stamp.sec >= 100] == list(range(100, 300))
    with next(repaired.glob('*.mcap')).open('rb') as stream:  # the mcap reader, via its summary
        summary = make_reader(stream).get_summary()
    assert summary is not None and summary.statistics.message_count == poses.t.size
    assert mcap_doctor(repaired) == ''


@pytest.mark.parametrize('sig', [signal.SIGINT, signal.SIGTERM])
def test_a_signal_closes_the_bag_cleanly(ros_graph, tmp_path, sig, mcap_doctor):
    out = tmp_path / 'clean'
    proc = _start_recorder(ros_graph, out, '/tip_pose', '/tip_load')
    try:
        ros_graph.publish('/tip_load', Float64(data=4.5))
        _publish_poses(ros_graph, 50)
        ros_graph.publish('/tip_load', Float64(data=0.0))
        ros_graph.spin_for(0.3)
    finally:
        proc.send_signal(sig)
        stdout, stderr = proc.communicate(timeout=15)
    assert proc.returncode == 0, stderr
    assert 'recorded' in stdout and '/tip_pose 5' in stdout
    reader = BagReader(out)
    assert not reader.truncated
    assert reader.topics['/tip_pose'].count == read_tip_poses(reader).t.size >= 50
    assert read_load_events(reader).changes().kg[-1] == 0.0
    assert mcap_doctor(out) == ''


@pytest.mark.parametrize(
    ('argv', 'match'),
    [
        (['record', '{out}'], 'name the topics to record, or pass --all'),
        (['record', '{out}', '/a', '--all'], 'either topics or --all'),
        (['record', '{existing}', '/a'], 'exists already; a bag is never overwritten'),
        (['record', '{file}/bag', '/a'], 'cannot create bag'),
        (
            ['record', '{out}', '/a', '--namespace', 'beam_a'],
            "--namespace 'beam_a': namespace must be absolute, it must lead with a '/'",
        ),
        (
            ['record', '{out}', '/a', '--namespace', '/beam_a/'],
            "--namespace '/beam_a/': namespace must not end with a '/'",
        ),
        (
            ['record', '--duration', '0.5', '{out}', '/bad topic!'],
            "topic '/bad topic!': topic name must not contain characters other than",
        ),
        (
            ['record', '--duration', '0.5', '{out}', '/tip_pose', '/a//b'],
            "topic '/a//b': topic name must not contain repeated '/'",
        ),
        (
            ['record', '--duration', '0.5', '{out}', '/tip_pose/'],
            "topic '/tip_pose/': topic name must not end with",
        ),
        (
            ['record', '--duration', '0.5', '{out}', '9lives'],
            "topic '9lives': topic name token must not start with a number",
        ),
    ],
)
def test_bad_invocations_print_one_line(tmp_path, capsys, argv, match):
    (tmp_path / 'existing').mkdir()
    (tmp_path / 'file').write_text('x')
    paths = {'out': tmp_path / 'out', 'existing': tmp_path / 'existing', 'file': tmp_path / 'file'}
    assert main([a.format(**paths) for a in argv]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith('lumpbeam record: error: ')
    assert match in err and '\n' not in err
    assert not (tmp_path / 'out').exists()  # nothing was created


def test_a_namespaced_recorder_stores_its_topics_under_the_bag_names(ros_graph, tmp_path):
    out = tmp_path / 'spaced'
    proc = _start_recorder(ros_graph, out, '/tip_pose', '--namespace', '/beam_a')
    try:
        _publish_poses(ros_graph, 20, topic='/beam_a/tip_pose')
        ros_graph.spin_for(0.3)
    finally:
        proc.send_signal(signal.SIGINT)
        stdout, stderr = proc.communicate(timeout=15)
    assert proc.returncode == 0, stderr
    assert 'recorded 20 messages' in stdout and '/tip_pose 20' in stdout
    reader = BagReader(out)
    assert set(reader.topics) == {'/tip_pose'}
    np.testing.assert_array_equal(read_tip_poses(reader).t, 100.0 + np.arange(20))


def test_topics_may_follow_the_options(tmp_path, capsys, ros_domain_id, monkeypatch):
    monkeypatch.setenv('ROS_DOMAIN_ID', str(ros_domain_id))
    out = tmp_path / 'after'
    # A namespace of its own: the domain's graph may still list an earlier test's topics.
    args = ['--namespace', '/quiet', '--duration', '0.2', '/tip_pose', '/tip_load']
    assert main(['record', str(out), *args]) == 0
    printed = capsys.readouterr()
    assert 'recorded 0 messages' in printed.out
    assert '/tip_pose never appeared' in printed.out and '/tip_load never appeared' in printed.out
    assert BagReader(out).topics == {}
