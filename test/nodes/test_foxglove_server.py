"""The Foxglove server: a real WebSocket client on 127.0.0.1, channels from bags, the replay."""

import asyncio
import json
import socket
import struct

import foxglove
import pytest

from lumpbeam_ros.base.errors import BagError, LumpbeamError
from lumpbeam_ros.core.bagio import BagReader, BagWriter
from lumpbeam_ros.core.bagio.typestore import deserialize, type_description
from lumpbeam_ros.nodes.foxglove_server import (
    SUBPROTOCOL,
    ChannelSink,
    open_bag_channels,
    replay_bag,
    start_server,
)

websockets = pytest.importorskip('websockets')

HOST = '127.0.0.1'
POSE = 'geometry_msgs/msg/PoseStamped'
#: Foxglove WebSocket: a server's binary opcode for message data.
MESSAGE_DATA = 0x01
#: How long the client waits for one frame before the test sends again, s (not asserted).
RECEIVE_S = 0.2
#: A custom type the typestore does not know: its bag stores the definition.
CUSTOM = 'my_pkg/msg/Reading'


@pytest.fixture(scope='module')
def server():
    running = start_server(HOST, 0, name='lumpbeam-test')
    yield running
    running.stop()


@pytest.fixture
def sink(server):
    channels = ChannelSink()  # the SDK's global context: the server's
    yield channels
    channels.close()


@pytest.fixture(scope='module')
def bag(tmp_path_factory):
    """Poses at 100 Hz for 0.1 s, two loads, and a custom type with its definition."""
    path = tmp_path_factory.mktemp('fox') / 'bag'
    with BagWriter(path) as writer:
        writer.add_topic(
            '/reading', CUSTOM, msgdef='float64 value', type_hash='RIHS01_' + '0' * 64
        )
        for i in range(10):
            writer.write_pose('/tip_pose', 5.0 + i / 100, 2.3, -0.05 + i * 1e-4, 0.02)
        writer.write_float('/tip_load', 5.0, 4.5)
        writer.write_float('/tip_load', 5.05, 0.0)
        writer.write_raw('/reading', 5_000_000_000, b'\x00\x01\x00\x00' + struct.pack('<d', 1.5))
    return path


async def _receive(ws, timeout_s):
    """The next frame, or ``None`` when none comes within ``timeout_s``."""
    try:
        return await asyncio.wait_for(ws.recv(), timeout_s)
    except TimeoutError:
        return None


async def _advertised(ws, topics):
    """Reads frames until every topic is advertised; returns the channels by topic."""
    channels = {}
    while not set(topics) <= set(channels):
        frame = await _receive(ws, 10.0)
        assert frame is not None, f'not advertised: {set(topics) - set(channels)}'
        if isinstance(frame, str):
            message = json.loads(frame)
            if message['op'] == 'advertise':
                channels.update({c['topic']: c for c in message['channels']})
    return channels


async def _session(port, sink, topic, data, log_time_ns):
    """Connects, subscribes to ``topic`` and sends ``data`` until one message arrives.

    The server takes the subscription on its own thread, so a message logged before it has
    done so reaches nobody; the test sends again until the client gets one.
    """
    uri = f'ws://{HOST}:{port}'
    async with websockets.connect(uri, subprotocols=[SUBPROTOCOL], max_size=None) as ws:
        assert ws.subprotocol == SUBPROTOCOL
        channels = await _advertised(ws, [topic])
        request = {
            'op': 'subscribe',
            'subscriptions': [{'id': 7, 'channelId': channels[topic]['id']}],
        }
        await ws.send(json.dumps(request))
        for _ in range(100):
            sink.write_raw(topic, log_time_ns, memoryview(data))
            frame = await _receive(ws, RECEIVE_S)
            while isinstance(frame, str):
                frame = await _receive(ws, RECEIVE_S)
            if frame is not None and frame[0] == MESSAGE_DATA:
                subscription, log_time = struct.unpack_from('<IQ', frame, 1)
                return channels, subscription, log_time, bytes(frame[13:])
        raise AssertionError('no message reached the subscribed client')


def test_a_client_gets_the_channel_and_the_exact_bytes(server, sink, bag):
    sink.add_topic('/tip_pose', POSE)
    sink.add_topic('/tip_load', 'std_msgs/msg/Float64')
    assert sink.has_topic('/tip_pose') and not sink.has_topic('/nope')
    raw = next(BagReader(bag).iter_raw(['/tip_pose']))
    channels, subscription, log_time, payload = asyncio.run(
        _session(server.port, sink, '/tip_pose', bytes(raw.data), raw.log_time_ns)
    )
    channel = channels['/tip_pose']
    assert channel['encoding'] == 'cdr'
    assert channel['schemaName'] == POSE and channel['schemaEncoding'] == 'ros2msg'
    assert channel['schema'] == type_description(POSE)[0]
    assert channels['/tip_load']['schemaName'] == 'std_msgs/msg/Float64'
    assert subscription == 7 and log_time == raw.log_time_ns == 5_000_000_000
    assert payload == bytes(raw.data)
    assert deserialize(payload, POSE).header.frame_id == 'beam_base'
    assert sink.sent['/tip_pose'] >= 1 and sink.sent['/tip_load'] == 0


def test_a_taken_port_is_refused(server):
    # The SDK binds with address reuse: without the probe a second server would share it.
    with pytest.raises(LumpbeamError, match=rf'cannot serve on {HOST}:{server.port}: .*another'):
        start_server(HOST, server.port)


def test_a_port_held_by_another_program_is_refused():
    with socket.socket() as taken:
        taken.bind((HOST, 0))
        taken.listen()
        port = taken.getsockname()[1]
        with pytest.raises(LumpbeamError, match=f'cannot serve on {HOST}:{port}') as info:
            start_server(HOST, port)
    assert '\n' not in str(info.value)


def test_an_unknown_host_is_refused():
    with pytest.raises(LumpbeamError, match='cannot serve on no-such-host.invalid:8765'):
        start_server('no-such-host.invalid', 8765)


def test_an_unknown_type_without_definition_is_a_bag_error():
    sink = ChannelSink(foxglove.Context())
    with pytest.raises(BagError, match='my_pkg/msg/Nothing'):
        sink.add_topic('/x', 'my_pkg/msg/Nothing')
    assert not sink.has_topic('/x')


def test_a_given_definition_opens_the_channel():
    sink = ChannelSink(foxglove.Context())
    sink.add_topic('/reading', CUSTOM, msgdef='float64 value')
    sink.write_raw('/reading', 1, b'\x00\x01\x00\x00' + struct.pack('<d', 1.5))
    assert sink.sent == {'/reading': 1}


def test_writing_to_a_topic_without_a_channel_is_a_bag_error():
    sink = ChannelSink(foxglove.Context())
    sink.add_topic('/tip_pose', POSE)
    sink.close()
    assert not sink.has_topic('/tip_pose')
    with pytest.raises(BagError, match="topic '/tip_pose' has no channel"):
        sink.write_raw('/tip_pose', 0, b'')


@pytest.mark.parametrize(
    ('topics', 'served'),
    [
        (None, ['/tip_pose', '/tip_load']),  # /reading: no definition in the typestore
        (['/tip_load'], ['/tip_load']),
        (['/tip_load', '/reading'], ['/tip_load']),
    ],
    ids=['all', 'one', 'skips-unknown'],
)
def test_open_bag_channels_serves_the_known_types(bag, topics, served):
    sink = ChannelSink(foxglove.Context())
    reader = BagReader(bag)
    assert sorted(open_bag_channels(reader, sink, topics)) == sorted(served)
    assert open_bag_channels(reader, ChannelSink(foxglove.Context()), topics) == [
        t for t in reader.topics if t in served
    ]  # the bag's order
    assert all(sink.has_topic(t) for t in served)


@pytest.mark.parametrize(
    ('topics', 'match'),
    [
        (['/nope'], 'no topic /nope'),
        (['/tip_pose', '/a', '/b'], 'no topic /a, /b'),
        (['/reading'], 'none of its topics has a known message type'),
    ],
    ids=['missing', 'two-missing', 'only-unknown'],
)
def test_open_bag_channels_bad_topics(bag, topics, match):
    with pytest.raises(BagError, match=match):
        open_bag_channels(BagReader(bag), ChannelSink(foxglove.Context()), topics)


class _Recorder(ChannelSink):
    """A sink on a context of its own that also keeps what it was given."""

    def __init__(self):
        super().__init__(foxglove.Context())
        self.log = []

    def write_raw(self, topic, log_time_ns, data):
        super().write_raw(topic, log_time_ns, data)
        self.log.append((topic, log_time_ns, bytes(data)))


def test_replay_sends_every_message_in_log_order(bag):
    reader = BagReader(bag)
    sink = _Recorder()
    topics = open_bag_channels(reader, sink, None)
    assert replay_bag(reader, sink, topics, rate=1000.0) == 12
    expected = [(r.topic, r.log_time_ns, bytes(r.data)) for r in reader.iter_raw(topics)]
    assert sink.log == expected
    assert [t for _, t, _ in sink.log] == sorted(t for _, t, _ in sink.log)
    assert sink.sent == {'/tip_pose': 10, '/tip_load': 2}


def test_replay_loops_until_asked_to_stop(bag):
    reader = BagReader(bag)
    sink = _Recorder()
    open_bag_channels(reader, sink, ['/tip_pose'])
    sent = replay_bag(
        reader,
        sink,
        ['/tip_pose'],
        rate=1000.0,
        loop=True,
        should_stop=lambda: len(sink.log) >= 25,
    )
    assert sent == 25 == len(sink.log)
    assert [t for _, t, _ in sink.log[10:20]] == [t for _, t, _ in sink.log[:10]]


def test_replay_stopped_at_once_sends_nothing(bag):
    reader = BagReader(bag)
    sink = _Recorder()
    open_bag_channels(reader, sink, None)
    assert replay_bag(reader, sink, ['/tip_pose'], should_stop=lambda: True) == 0
    assert sink.log == []
