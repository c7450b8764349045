"""The player node: a bag back into the live graph, with the original timing and ``/clock``.

Messages are published in log-time order (the reader merges a file's chunks); a cut file,
read in file order, can hold one earlier than the last, which is published at once while
``/clock`` stays monotonic. Messages are published as their stored CDR bytes (rclpy's
``Publisher.publish(bytes)`` publishes serialized data), so nothing is deserialized.
Message ``i`` is published at wall time ``start + (log_time_i - log_time_0) / rate``;
``/clock`` carries the log time before each message, so nodes with ``use_sim_time`` follow
the bag. A gap between two messages longer than :data:`MAX_GAP_S` (after ``rate``) is played
as :data:`MAX_GAP_S` and counted (a bag whose stamps jump by days is not waited through);
``/clock`` still jumps as the bag does. The player sleeps in slices of at most
:data:`SLEEP_SLICE_S`, asking between them whether to stop, so a stop request is obeyed
within one slice whatever the gap. Each topic is published with the QoS its recorder was
offered, or the project's default (:mod:`lumpbeam_ros.core.bagio.qos`): best effort for images,
reliable transient-local for ``/tip_load``, reliable otherwise. Each topic is published by
its relative name: in a namespace (``/beam_a``) the bag's ``/tip_pose`` goes to
``/beam_a/tip_pose``; ``/clock`` stays graph-wide
(:func:`~lumpbeam_ros.base.interface.node_topic`).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np
from rclpy.context import Context
from rclpy.duration import Duration
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rosgraph_msgs.msg import Clock

from lumpbeam_ros.base.errors import BagError
from lumpbeam_ros.base.interface import CLOCK, PLAYER_NODE, node_topic
from lumpbeam_ros.core.bagio import BagReader
from lumpbeam_ros.core.bagio.qos import default_profile, from_dict
from lumpbeam_ros.nodes.msgtypes import from_bag_qos, message_class, topic_qos

#: Longest wait at the end of playback for reliable subscribers' acknowledgements, s.
DELIVERY_TIMEOUT_S = 5.0
#: The same wait after a stop request, s.
STOPPED_DELIVERY_TIMEOUT_S = 0.5
#: Longest wall-clock wait between two messages, s: a longer gap is shortened to it.
MAX_GAP_S = 5.0
#: Longest single sleep, s: a stop request waits at most this long to be seen.
SLEEP_SLICE_S = 0.1


def sleep_until(due: float, should_stop: Callable[[], bool]) -> bool:
    """Sleeps until ``time.perf_counter()`` reaches ``due``, in slices that check for a stop.

    Args:
        due: The ``time.perf_counter()`` value to wait for.
        should_stop: Polled before each slice.

    Returns:
        ``False`` when a stop was requested before ``due``.
    """
    while True:
        if should_stop():
            return False
        left = due - time.perf_counter()
        if left <= 0.0:
            return True
        time.sleep(min(left, SLEEP_SLICE_S))


@dataclass
class PlayStats:
    """What one pass over the bag did.

    Attributes:
        published: Messages published per topic.
        lateness_s: Publish time minus scheduled time of every message, s.
        delivered: Whether reliable subscribers acknowledged every message at the end.
        clock_published: ``/clock`` messages published (one before each message).
        out_of_order: Messages whose log time was before an earlier one's; they are
            published at once, and ``/clock`` holds its latest value rather than go back.
        gaps_shortened: Gaps longer than :data:`MAX_GAP_S` (wall time) played as that.
        longest_gap_s: The longest of them as the bag has it, s (0 when none).
        stopped: Whether a stop request ended the pass early.
    """

    published: dict[str, int] = field(default_factory=dict)
    lateness_s: list[float] = field(default_factory=list)
    delivered: bool = True
    clock_published: int = 0
    out_of_order: int = 0
    gaps_shortened: int = 0
    longest_gap_s: float = 0.0
    stopped: bool = False

    def lateness_percentile_ms(self, q: float) -> float:
        """Returns a percentile of the lateness, ms (0 when nothing was published)."""
        return float(np.percentile(self.lateness_s, q) * 1e3) if self.lateness_s else 0.0


class Player(Node):
    """Publishes a bag's messages.

    Args:
        reader: The open bag.
        topics: Topics to play; all of the bag's when ``None``.
        rate: Playback speed factor (2.0 plays twice as fast).
        context: The rclpy context.
        namespace: Publish the bag's topics in this namespace (``'/beam_a'``).

    Raises:
        BagError: A requested topic is not in the bag, or its type is not installed.
    """

    def __init__(
        self,
        reader: BagReader,
        topics: Sequence[str] | None = None,
        rate: float = 1.0,
        context: Context | None = None,
        namespace: str = '',
    ):
        super().__init__(PLAYER_NODE, context=context, namespace=namespace)
        if not rate > 0.0:
            raise BagError(f'playback rate must be positive, got {rate!r}')
        self.reader = reader
        self.rate = rate
        names = list(reader.topics) if topics is None else list(topics)
        self._outlets = {}
        for name in names:
            entry = reader.require(name)
            cls = message_class(entry.msgtype)
            outlet = node_topic(name)
            self._outlets[name] = self.create_publisher(cls, outlet, self._qos(name, entry))
        self._clock = self.create_publisher(Clock, CLOCK, topic_qos(CLOCK))

    def play(self, should_stop: Callable[[], bool] = lambda: False) -> PlayStats:
        """Plays the bag once, sleeping between messages to keep their relative timing.

        Args:
            should_stop: Polled between messages; ``True`` ends playback early.

        Returns:
            Counts and timing.
        """
        stats = PlayStats({name: 0 for name in self._outlets})
        start_wall = None
        first_ns = 0
        clock_ns = 0
        skipped_s = 0.0  # wall time taken out of long gaps
        clock = Clock()
        for raw in self.reader.iter_raw(self._outlets):
            if should_stop():
                stats.stopped = True
                break
            if start_wall is None:
                start_wall, first_ns = time.perf_counter(), raw.log_time_ns
            gap_s = (raw.log_time_ns - max(clock_ns, first_ns)) * 1e-9 / self.rate
            if gap_s > MAX_GAP_S:
                stats.gaps_shortened += 1
                stats.longest_gap_s = max(stats.longest_gap_s, gap_s * self.rate)
                skipped_s += gap_s - MAX_GAP_S
            due = start_wall + (raw.log_time_ns - first_ns) * 1e-9 / self.rate - skipped_s
            if not sleep_until(due, should_stop):
                stats.stopped = True
                break
            if raw.log_time_ns < clock_ns:
                stats.out_of_order += 1  # a cut file is read in file order: never turn back
            clock_ns = max(clock_ns, raw.log_time_ns)
            clock.clock.sec, clock.clock.nanosec = divmod(clock_ns, 1_000_000_000)
            self._clock.publish(clock)
            stats.clock_published += 1
            self._outlets[raw.topic].publish(bytes(raw.data))
            stats.lateness_s.append(time.perf_counter() - due)
            stats.published[raw.topic] += 1
        # Stopped: a short wait only, the stop must not take longer than a user waits.
        stats.delivered = self.wait_for_delivery(
            STOPPED_DELIVERY_TIMEOUT_S if stats.stopped else DELIVERY_TIMEOUT_S
        )
        return stats

    def wait_for_subscribers(
        self, timeout_s: float, should_stop: Callable[[], bool] = lambda: False
    ) -> list[str]:
        """Waits until every played topic has a matched subscriber, at most ``timeout_s``.

        Args:
            timeout_s: Longest wait, s.
            should_stop: Polled while waiting; ``True`` ends the wait.

        Returns:
            The topics still without one (empty when all are heard).
        """
        deadline = time.monotonic() + timeout_s
        while True:
            unheard = [
                name for name, pub in self._outlets.items() if pub.get_subscription_count() == 0
            ]
            if not unheard or time.monotonic() >= deadline or should_stop():
                return unheard
            time.sleep(0.05)

    def wait_for_delivery(self, timeout_s: float = DELIVERY_TIMEOUT_S) -> bool:
        """Waits until reliable subscribers have acknowledged everything published.

        A player that exits right after its last message can take that message with it: the
        DDS writer goes before the reader's acknowledgement arrives.

        Args:
            timeout_s: Longest wait, shared by all publishers, s.

        Returns:
            Whether everything was acknowledged in time (best-effort topics always are).
        """
        deadline = time.monotonic() + timeout_s
        delivered = True
        for publisher in [*self._outlets.values(), self._clock]:
            left = max(0.0, deadline - time.monotonic())
            delivered &= publisher.wait_for_all_acked(Duration(seconds=left))
        return delivered

    @staticmethod
    def _qos(name: str, entry: object) -> QoSProfile:
        offered = [from_dict(p) for p in getattr(entry, 'qos', []) if isinstance(p, dict)]
        if not offered:
            return from_bag_qos(default_profile(name, getattr(entry, 'msgtype', '')))
        profile = from_bag_qos(offered[0])
        # Offer the strongest policy any recorded publisher offered: it matches every
        # subscriber that any of them matched.
        if any(from_bag_qos(q).reliability == ReliabilityPolicy.RELIABLE for q in offered):
            profile.reliability = ReliabilityPolicy.RELIABLE
        if any(from_bag_qos(q).durability == DurabilityPolicy.TRANSIENT_LOCAL for q in offered):
            profile.durability = DurabilityPolicy.TRANSIENT_LOCAL
        return profile
