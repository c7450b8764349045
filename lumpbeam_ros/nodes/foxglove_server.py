"""Serving topics to Foxglove over its WebSocket protocol, with the Foxglove SDK.

Messages go out as their CDR bytes on channels whose schema is the ``ros2msg`` definition of
their type (what ``ros2 bag`` stores, from the Jazzy typestore), so Foxglove decodes them as
it decodes a ROS 2 bag or ``foxglove_bridge``: nothing is converted on the way.

:class:`ChannelSink` has the recording interface of :class:`~lumpbeam_ros.core.bagio.BagWriter`
(``add_topic``, ``write_raw``, ``flush``), so the recorder node's graph discovery and raw
subscriptions serve the live graph unchanged; :func:`replay_bag` paces a bag's messages by
their log times instead.
"""

from __future__ import annotations

import heapq
import socket
import time
from collections.abc import Callable, Sequence
from typing import Any

from lumpbeam_ros.base.errors import BagError, LumpbeamError
from lumpbeam_ros.core.bagio import BagReader
from lumpbeam_ros.core.bagio.reader import RawMessage
from lumpbeam_ros.core.bagio.typestore import is_known, type_description

#: The WebSocket subprotocol the SDK's server speaks: the successor of
#: ``foxglove.websocket.v1`` under a new name (same advertise, subscribe and message-data
#: messages); the Foxglove app speaks both.
SUBPROTOCOL = 'foxglove.sdk.v1'
#: Longest sleep between two checks of the stop request, s.
POLL_S = 0.05


def start_server(host: str, port: int, name: str = 'lumpbeam') -> Any:
    """Starts the SDK's WebSocket server.

    Args:
        host: Address to listen on.
        port: TCP port (0: any free one).
        name: The server's name, as Foxglove shows it.

    Returns:
        The running :class:`foxglove.WebSocketServer` (its ``port`` is the one bound).

    Raises:
        LumpbeamError: The port is taken or the address cannot be bound.
    """
    import foxglove

    if port != 0:
        _check_free(host, port)
    try:
        return foxglove.start_server(name=name, host=host, port=port)
    except Exception as exc:  # the SDK raises its own RuntimeError subclasses
        raise LumpbeamError(f'cannot serve on {host}:{port}: {exc}') from None


def _check_free(host: str, port: int) -> None:
    """Raises if ``host:port`` cannot be bound exclusively.

    The SDK's server binds with address reuse, so a second ``lumpbeam view`` on a taken port
    would start and share it silently; a plain bind first tells the user instead.
    """
    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM)
    except socket.gaierror as exc:
        raise LumpbeamError(f'cannot serve on {host}:{port}: {exc.strerror}') from None
    family, kind, proto, _, address = infos[0]
    with socket.socket(family, kind, proto) as probe:
        # As a server binds (the SDK's too): the connections of a server just stopped, left in
        # TIME_WAIT, do not hold the port; a server still listening on it does.
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            probe.bind(address)
        except OSError as exc:
            raise LumpbeamError(
                f'cannot serve on {host}:{port}: {exc.strerror} (another server uses the port?)'
            ) from None


class ChannelSink:
    """Foxglove channels that take CDR bytes: the recording interface of ``BagWriter``.

    Args:
        context: A ``foxglove.Context`` (``None``: the SDK's global one, the server's).
    """

    def __init__(self, context: Any = None):
        self._context = context
        self._channels: dict[str, Any] = {}
        self.sent: dict[str, int] = {}
        self._latest_log_time_ns = -1

    def has_topic(self, topic: str) -> bool:
        """Whether a channel was opened for the topic."""
        return topic in self._channels

    def add_topic(
        self,
        topic: str,
        msgtype: str,
        qos: Sequence[Any] | None = None,
        msgdef: str | None = None,
        type_hash: str | None = None,
    ) -> None:
        """Opens (advertises) a channel for a topic.

        Args:
            topic: Topic name.
            msgtype: Full type name.
            qos: Ignored (the WebSocket has no QoS); for ``BagWriter``'s signature.
            msgdef: ``ros2msg`` definition; from the typestore when ``None``.
            type_hash: Ignored.

        Raises:
            BagError: A type neither known nor described.
        """
        import foxglove

        if msgdef is None:
            msgdef, _ = type_description(msgtype)
        schema = foxglove.Schema(name=msgtype, encoding='ros2msg', data=msgdef.encode())
        self._channels[topic] = foxglove.Channel(
            topic, schema=schema, message_encoding='cdr', context=self._context
        )
        self.sent[topic] = 0

    def write_raw(self, topic: str, log_time_ns: int, data: bytes | memoryview) -> None:
        """Sends one CDR message to the clients subscribed to its channel."""
        channel = self._channels.get(topic)
        if channel is None:
            raise BagError(f'topic {topic!r} has no channel')
        channel.log(bytes(data), log_time=int(log_time_ns))
        self.sent[topic] += 1
        self._latest_log_time_ns = max(self._latest_log_time_ns, int(log_time_ns))

    @property
    def flushed_log_time_ns(self) -> int:
        """The latest log time sent (-1 before the first message), ns: nothing waits to go."""
        return self._latest_log_time_ns

    def flush(self) -> None:
        """Nothing is buffered: every message is sent as it comes."""

    def close(self) -> None:
        """Closes (unadvertises) every channel."""
        for channel in self._channels.values():
            channel.close()
        self._channels.clear()


def open_bag_channels(
    reader: BagReader, sink: ChannelSink, topics: Sequence[str] | None
) -> list[str]:
    """Opens a channel per topic of a bag that Foxglove can decode.

    Args:
        reader: The bag.
        sink: Where the channels open.
        topics: Only these (``None``: all).

    Returns:
        The topics served, in the bag's order.

    Raises:
        BagError: A requested topic is not in the bag, or no topic can be served.
    """
    wanted = list(reader.topics) if topics is None else list(topics)
    missing = [t for t in wanted if t not in reader.topics]
    if missing:
        raise BagError(f'{reader.path}: no topic {", ".join(missing)}')
    served = []
    for topic in wanted:
        msgtype = reader.topics[topic].msgtype
        if is_known(msgtype):
            sink.add_topic(topic, msgtype)
            served.append(topic)
    if not served:
        raise BagError(f'{reader.path}: none of its topics has a known message type')
    return served


def replay_bag(
    reader: BagReader,
    sink: ChannelSink,
    topics: Sequence[str],
    *,
    rate: float = 1.0,
    loop: bool = False,
    should_stop: Callable[[], bool] = lambda: False,
    extra: Sequence[RawMessage] = (),
) -> int:
    """Sends a bag's messages with their original relative timing.

    Args:
        reader: The bag.
        sink: Channels opened by :func:`open_bag_channels`.
        topics: The topics to send.
        rate: Speed factor.
        loop: Start again at the end.
        should_stop: Polled between messages and while waiting; true stops the replay.
        extra: More messages (their channels opened), in log-time order, sent among the
            bag's by log time (markers drawn for the bag).

    Returns:
        How many messages were sent.
    """
    sent = 0
    while True:
        start_wall, first_log = time.monotonic(), None
        stream = heapq.merge(reader.iter_raw(list(topics)), extra, key=lambda m: m.log_time_ns)
        for raw in stream:
            first_log = raw.log_time_ns if first_log is None else first_log
            due = start_wall + (raw.log_time_ns - first_log) / 1e9 / rate
            while (wait := due - time.monotonic()) > 0.0:
                if should_stop():
                    return sent
                time.sleep(min(wait, POLL_S))
            if should_stop():
                return sent
            sink.write_raw(raw.topic, raw.log_time_ns, raw.data)
            sent += 1
        if not loop or should_stop() or first_log is None:
            return sent
