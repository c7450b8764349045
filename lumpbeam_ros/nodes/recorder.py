"""The recorder node: live topics into a rosbag2/MCAP bag, serialized bytes straight to disk.

Topics are discovered from the graph (``get_topic_names_and_types``) and subscribed with
``raw=True``, so each message arrives as its CDR bytes and is written without being
deserialized. Each topic's offered QoS (from ``get_publishers_info_by_topic``) goes into the
bag's metadata; the subscription matches it (best effort if any publisher is, transient local
only if every publisher is, so a latched ``/tip_load`` is received on joining). The bag is
flushed at least every ``flush_period_s`` (see :class:`~lumpbeam_ros.core.bagio.BagWriter`), so a
killed recorder loses at most that much. A message's log time is the time the middleware
received it (the message info's ``received_timestamp``, wall clock), as rosbag2 records it: the
time the callback runs would date a message that waited in the queue behind others too late,
and put ``/tip_load`` out of its order with ``/clock`` on a busy machine. The writer sorts what
it holds by log time, so the bag is in log-time order.

A bag holds the interface's names (``/tip_pose``). A recorder in a namespace (``/beam_a``)
records that beam's topics (``/beam_a/tip_pose``) under those names, and the graph-wide ones
(``/clock``) as they are; a player in the same namespace publishes them back where they were.
"""

from __future__ import annotations

import time
from collections.abc import Sequence

from rclpy.context import Context
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import GLOBAL_TOPICS, RECORDER_NODE
from lumpbeam_ros.core.bagio import BagWriter
from lumpbeam_ros.core.bagio.qos import STREAM_DEPTH
from lumpbeam_ros.core.bagio.typestore import is_known
from lumpbeam_ros.nodes.msgtypes import message_class, to_bag_qos

#: Subscription depth of a best-effort topic (images): a 180 fps camera must not overflow it
#: between two executor turns. Reliable topics take the project's stream depth
#: (:data:`~lumpbeam_ros.core.bagio.qos.STREAM_DEPTH`, more than a second of 180 Hz poses).
DEPTH = 200


class Recorder(Node):
    """Subscribes to topics as they appear and writes them into a bag.

    Args:
        bag: An open writer; the node writes into it, the caller closes it.
        topics: Topics to record; ``None`` records every topic (``--all``).
        context: The rclpy context.
        discovery_period_s: How often the graph is scanned for new topics, s.
        flush_period_s: How often pending messages are flushed to disk, s.
        namespace: Record this namespace's topics (``'/beam_a'``), named as without it.
    """

    def __init__(
        self,
        bag: BagWriter,
        topics: Sequence[str] | None,
        context: Context | None = None,
        discovery_period_s: float = 0.2,
        flush_period_s: float = 0.5,
        namespace: str = '',
    ):
        super().__init__(RECORDER_NODE, context=context, namespace=namespace)
        self.bag = bag
        self.wanted = None if topics is None else {_absolute(t) for t in topics}
        self.received: dict[str, int] = {}
        self.error: LumpbeamError | None = None
        self._skipped: set[str] = set()
        self._taps: dict[str, object] = {}
        self.create_timer(discovery_period_s, self.discover)
        self.create_timer(flush_period_s, self._flush)
        self.discover()

    def discover(self) -> None:
        """Subscribes to wanted topics that have publishers and no subscription yet."""
        for graph_topic, types in self.get_topic_names_and_types():
            topic = self.bag_topic(graph_topic)
            if topic is None or topic in self._taps or topic in self._skipped:
                continue
            if self.wanted is None:
                if topic in ('/rosout', '/parameter_events'):
                    continue
            elif topic not in self.wanted:
                continue
            self._subscribe(topic, types, graph_topic)

    def bag_topic(self, graph_topic: str) -> str | None:
        """The name a graph topic has in the bag; ``None`` when outside the namespace.

        Args:
            graph_topic: A fully qualified name, e.g. ``'/beam_a/tip_pose'``.

        Returns:
            E.g. ``'/tip_pose'`` in namespace ``/beam_a``; the name itself without a namespace.
        """
        namespace = self.get_namespace()
        if namespace == '/' or graph_topic in GLOBAL_TOPICS:
            return graph_topic
        prefix = f'{namespace}/'
        return graph_topic[len(prefix) - 1 :] if graph_topic.startswith(prefix) else None

    def missing(self) -> list[str]:
        """Wanted topics not seen yet (empty with ``--all``)."""
        return sorted((self.wanted or set()) - set(self._taps))

    def _subscribe(self, topic: str, types: list[str], graph_topic: str) -> None:
        msgtype = types[0]
        if len(types) > 1:
            self.get_logger().warning(f'{topic} has several types {types}; recording {msgtype}')
        if not is_known(msgtype):
            self.get_logger().warning(f'not recording {topic}: no definition of {msgtype}')
            self._skipped.add(topic)
            return
        try:
            cls = message_class(msgtype)
        except LumpbeamError as exc:
            self.get_logger().warning(f'not recording {topic}: {exc}')
            self._skipped.add(topic)
            return
        infos = self.get_publishers_info_by_topic(graph_topic)
        offered = [info.qos_profile for info in infos]
        best_effort = any(p.reliability == ReliabilityPolicy.BEST_EFFORT for p in offered)
        latched = bool(offered) and all(
            p.durability == DurabilityPolicy.TRANSIENT_LOCAL for p in offered
        )
        qos = QoSProfile(
            history=HistoryPolicy.KEEP_LAST,
            depth=DEPTH if best_effort else STREAM_DEPTH,
            reliability=ReliabilityPolicy.BEST_EFFORT
            if best_effort
            else ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.TRANSIENT_LOCAL if latched else DurabilityPolicy.VOLATILE,
        )
        self.bag.add_topic(topic, msgtype, qos=[to_bag_qos(p) for p in offered])
        self.received[topic] = 0

        def write(data: bytes, info: dict[str, int], topic: str = topic) -> None:
            if self.error is not None:
                return
            received = info.get('received_timestamp') or time.time_ns()
            # Never before what was flushed already: a wall clock stepped back (NTP) must not
            # put the bag out of log-time order.
            log_ns = max(received, self.bag.flushed_log_time_ns)
            try:
                self.bag.write_raw(topic, log_ns, data)
            except LumpbeamError as exc:
                self.error = exc  # the caller stops spinning and reports it
                return
            self.received[topic] += 1

        self._taps[topic] = self.create_subscription(cls, graph_topic, write, qos, raw=True)
        self.get_logger().info(f'recording {graph_topic} ({msgtype}) as {topic}')

    def _flush(self) -> None:
        if self.error is None:
            try:
                self.bag.flush()
            except LumpbeamError as exc:
                self.error = exc


def _absolute(topic: str) -> str:
    return topic if topic.startswith('/') else f'/{topic}'
