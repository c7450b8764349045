"""``lumpbeam view``: a bag served to a real WebSocket client over Foxglove's protocol."""

import asyncio
import json
import re
import signal
import socket
import struct
import subprocess
import sys

import numpy as np
import pytest
import yaml
from arm_cases import small_arm, small_arm_document

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.core.bagio.typestore import deserialize
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.model.parameters import load_beam_config
from lumpbeam_ros.core.synthetic.arm_bag import ArmSynthOptions, write_arm_bag
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, write_drop_test_bag
from lumpbeam_ros.nodes.foxglove_server import SUBPROTOCOL

websockets = pytest.importorskip('websockets')

#: Foxglove WebSocket v1: a server's binary message opcode for message data.
MESSAGE_DATA = 0x01
#: The status a Foxglove SDK server answers a subscription to a channel it does not know with.
UNKNOWN_CHANNEL = re.compile(r'Unknown channel ID: (\d+)')
WANTED = {
    '/tip_pose': 'geometry_msgs/msg/PoseStamped',
    '/beam_markers': 'visualization_msgs/msg/MarkerArray',
}


@pytest.fixture(scope='module')
def bag(tmp_path_factory):
    path = tmp_path_factory.mktemp('view') / 'drop'
    beam, drop = load_beam_config()
    write_drop_test_bag(path, beam, drop, SynthOptions(duration_s=2.5))
    return path


@pytest.fixture(scope='module')
def arm_bag(tmp_path_factory):
    """A two-link arm's synthetic bag (``lumpbeam synth --arm``): it carries the arm's markers."""
    path = tmp_path_factory.mktemp('view') / 'arm'
    t = np.arange(0.0, 0.2 + 1e-9, 0.01)
    move = JointTrajectory(t, np.outer(t, [2.0, -2.0]))
    write_arm_bag(path, small_arm(2), move, ArmSynthOptions(duration_s=0.5))
    return path


def _serve(bag, *extra):
    """``lumpbeam view --bag BAG --port 0 --loop`` in a child process, and its port."""
    process = subprocess.Popen(
        [sys.executable, '-m', 'lumpbeam_ros.apps.cli.main', 'view', '--bag', str(bag), *extra]
        + ['--port', '0', '--loop', '--duration', '60'],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    line = process.stdout.readline()
    if extra:
        line = process.stdout.readline()  # after the line on the markers drawn
    match = re.search(r'at ws://127\.0\.0\.1:(\d+)', line)
    assert match, f'no address announced: {line!r} {process.stderr.read() if not line else ""}'
    return process, int(match.group(1))


def _stop(process):
    if process.poll() is None:
        process.send_signal(signal.SIGINT)
        process.wait(10)


@pytest.fixture
def server(bag):
    process, port = _serve(bag)
    yield process, port
    _stop(process)


async def _watch(port, timeout_s=20.0, wanted=WANTED):
    """Connects, subscribes to ``wanted`` and returns (channels, first payload per topic)."""
    uri = f'ws://127.0.0.1:{port}'
    async with websockets.connect(uri, subprotocols=[SUBPROTOCOL], max_size=None) as ws:
        assert ws.subprotocol == SUBPROTOCOL
        channels, payloads, subscriptions = {}, {}, {}
        loop = asyncio.get_running_loop()
        deadline = loop.time() + timeout_s
        while len(payloads) < len(wanted):
            frame = await asyncio.wait_for(ws.recv(), deadline - loop.time())
            if isinstance(frame, str):
                message = json.loads(frame)
                unknown = message['op'] == 'status' and UNKNOWN_CHANNEL.match(message['message'])
                if unknown:
                    # The SDK sends a live channel's advertisement before it records the
                    # channel as advertised (ConnectedClient::advertise_channels), so an
                    # answer fast enough is refused: ask once more, as a robust client does.
                    channel_id = int(unknown.group(1))
                    request = [
                        {'id': i, 'channelId': channel_id}
                        for i, t in subscriptions.items()
                        if channels[t]['id'] == channel_id
                    ]
                    await ws.send(json.dumps({'op': 'subscribe', 'subscriptions': request}))
                elif message['op'] == 'advertise':
                    channels.update({c['topic']: c for c in message['channels']})
                    if not subscriptions and set(wanted) <= set(channels):
                        subscriptions = {i: t for i, t in enumerate(wanted, start=1)}
                        request = [
                            {'id': i, 'channelId': channels[t]['id']}
                            for i, t in subscriptions.items()
                        ]
                        await ws.send(json.dumps({'op': 'subscribe', 'subscriptions': request}))
            elif frame[0] == MESSAGE_DATA:
                subscription, _log_time = struct.unpack_from('<IQ', frame, 1)
                payloads.setdefault(subscriptions[subscription], bytes(frame[13:]))
        return channels, payloads


def test_a_client_gets_the_channels_and_messages_of_a_bag(server):
    process, port = server
    channels, payloads = asyncio.run(_watch(port))
    assert {'/tip_pose', '/tip_load', '/tip_pose_truth', '/beam_markers'} == set(channels)
    for topic, msgtype in WANTED.items():
        channel = channels[topic]
        assert channel['encoding'] == 'cdr'
        assert channel['schemaName'] == msgtype and channel['schemaEncoding'] == 'ros2msg'
        message = deserialize(payloads[topic], msgtype)  # the bag's CDR bytes, unchanged
        if topic == '/tip_pose':
            assert message.header.frame_id == 'beam_base'
        else:
            assert {m.ns for m in message.markers} >= {'beam', 'tip_measured', 'board'}
    process.send_signal(signal.SIGINT)
    assert process.wait(10) == 0
    assert 'stopped after' in process.stdout.read()


def test_an_arm_bag_is_served_with_the_whole_arm(arm_bag):
    wanted = {
        '/joint_states': 'sensor_msgs/msg/JointState',
        '/beam_markers': 'visualization_msgs/msg/MarkerArray',
    }
    process, port = _serve(arm_bag)
    try:
        channels, payloads = asyncio.run(_watch(port, wanted=wanted))
    finally:
        _stop(process)
    assert {'/joint_states', '/tip_pose', '/tip_pose_truth', '/beam_markers'} == set(channels)
    joints = deserialize(payloads['/joint_states'], wanted['/joint_states'])
    assert list(joints.name) == ['joint_1', 'joint_2']
    markers = deserialize(payloads['/beam_markers'], wanted['/beam_markers']).markers
    links = [m for m in markers if m.ns == 'arm_link']
    assert [len(m.points) for m in links] == [5, 4]  # 4 and 3 segments, joint to joint
    assert {m.ns for m in markers} >= {'arm_joints', 'tip_measured'}


@pytest.mark.slow  # the child simulates the arm before serving: some 8 s on a loaded machine
def test_a_recorded_arm_is_drawn_from_its_joint_states(tmp_path):
    # A real arm's bag: joint states and tip poses, no markers; --arm draws the model's arm.
    t = np.arange(0.0, 0.2 + 1e-9, 0.01)
    move = JointTrajectory(t, np.outer(t, [2.0, -2.0]))
    options = ArmSynthOptions(duration_s=0.5, rate_hz=40.0, markers_rate_hz=0)
    write_arm_bag(tmp_path / 'recorded', small_arm(2), move, options)
    arm = tmp_path / 'arm.yaml'
    arm.write_text(yaml.safe_dump(small_arm_document(2)))
    wanted = {'/beam_markers': 'visualization_msgs/msg/MarkerArray'}
    process, port = _serve(tmp_path / 'recorded', '--arm', str(arm))
    try:
        channels, payloads = asyncio.run(_watch(port, wanted=wanted))
    finally:
        _stop(process)
    assert '/beam_markers' in channels and '/joint_states' in channels
    markers = deserialize(payloads['/beam_markers'], wanted['/beam_markers']).markers
    assert [len(m.points) for m in markers if m.ns == 'arm_link'] == [5, 4]


def test_arm_without_a_bag_is_one_line_and_exit_2(capsys, tmp_path):
    assert main(['view', '--port', '0', '--arm', str(tmp_path / 'arm.yaml')]) == 2
    err = capsys.readouterr().err
    assert '--arm draws a bag: give --bag too' in err and len(err.strip().splitlines()) == 1


def test_a_taken_port_is_one_line_and_exit_2(bag, capsys):
    with socket.socket() as taken:
        taken.bind(('127.0.0.1', 0))
        taken.listen()
        port = taken.getsockname()[1]
        assert main(['view', '--bag', str(bag), '--port', str(port)]) == 2
    err = capsys.readouterr().err
    assert f'cannot serve on 127.0.0.1:{port}' in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize(
    ('args', 'message'),
    [
        (['--bag', '/no/such/bag'], 'no such bag'),
        (['--topics', '/nope'], 'no topic /nope'),
    ],
)
def test_bad_input_is_one_line_and_exit_2(bag, capsys, args, message):
    argv = ['view', '--port', '0', *args]
    if '--bag' not in args:
        argv += ['--bag', str(bag)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1


def test_a_port_out_of_range_is_a_usage_error(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(['view', '--port', '70000'])
    assert exit_info.value.code == 2
    assert 'port must be in 0..65535' in capsys.readouterr().err.splitlines()[-1]


def _serve_live(domain_id, port='0'):
    """``lumpbeam view`` on the live graph of a test's domain, and the port it serves."""
    from harness import ros_env

    process = subprocess.Popen(
        [sys.executable, '-m', 'lumpbeam_ros.apps.cli.main', 'view', '--port', port]
        + ['--duration', '60'],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=ros_env(domain_id),
    )
    line = process.stdout.readline()
    match = re.search(r'at ws://127\.0\.0\.1:(\d+)', line)
    assert match, f'no address announced: {line!r} {process.stderr.read() if not line else ""}'
    return process, int(match.group(1))


def test_the_live_graph_is_served_and_the_port_is_free_at_once_after(ros_graph):
    # A node publishing on the graph; the viewer forwards it to a WebSocket client.
    import threading

    from geometry_msgs.msg import PoseStamped

    process, port = _serve_live(ros_graph.domain_id)
    done = threading.Event()

    def publish():
        msg = PoseStamped()
        msg.header.frame_id = 'beam_base'
        while not done.is_set():
            msg.pose.position.z = -0.04
            ros_graph.publish('/tip_pose', msg)
            done.wait(0.05)

    publisher = threading.Thread(target=publish, daemon=True)
    publisher.start()
    try:
        wanted = {'/tip_pose': 'geometry_msgs/msg/PoseStamped'}
        channels, payloads = asyncio.run(_watch(port, wanted=wanted))
    except TimeoutError:
        done.set()
        _stop(process)
        pytest.fail(
            f'no /tip_pose served in 20 s; the viewer said: {process.stderr.read()[-3000:]}'
        )
    finally:
        done.set()
        publisher.join(5)
        _stop(process)
    assert channels['/tip_pose']['schemaName'] == wanted['/tip_pose']
    pose = deserialize(payloads['/tip_pose'], wanted['/tip_pose'])
    assert pose.pose.position.z == -0.04 and process.returncode == 0
    # A client has been connected: the port is taken up again at once by the next viewer.
    again, again_port = _serve_live(ros_graph.domain_id, str(port))
    _stop(again)
    assert again_port == port and again.returncode == 0
