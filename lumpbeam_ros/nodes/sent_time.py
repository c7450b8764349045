"""When a message without a stamp was sent, on the receiving node's clock.

A ``std_msgs/Float64`` such as ``/tip_load`` carries no stamp, and its callback may run well
after it was sent (a busy executor, a loaded machine), when ``/clock`` has moved on. DDS
stamps every sample with its writer's wall time (``source_timestamp`` in rclpy's message
info): on wall time that is the send time itself, and under ``use_sim_time`` the ``/clock``
samples' own source timestamps map it onto the simulated clock.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Mapping

#: A send time further back than this from the node's clock is another host's clock, not a
#: delay, s: the message is dated by the node's clock instead.
MAX_DELAY_S = 5.0

#: ``/clock`` samples kept to map send times (a player sends one before each message: some
#: seconds of a bag).
KEPT_CLOCKS = 4096


def sent_ns(info: Mapping[str, int] | None) -> int:
    """A message's DDS source timestamp, ns (0: unknown).

    Args:
        info: rclpy's message info, as passed to a callback taking two arguments.
    """
    return int((info or {}).get('source_timestamp', 0))


class SentClock:
    """Dates a message by when it was sent, on the node's clock.

    Args:
        sim_time: The node runs on ``/clock`` (``use_sim_time``); feed :meth:`clock_sent`.
    """

    def __init__(self, sim_time: bool):
        self.sim_time = sim_time
        self._clocks: deque[tuple[int, float]] = deque(maxlen=KEPT_CLOCKS)

    def clock_sent(self, sent: int, clock_s: float) -> None:
        """Notes a ``/clock`` sample: its source timestamp (ns) and the time it carries (s)."""
        if sent > 0 and (not self._clocks or sent >= self._clocks[-1][0]):
            self._clocks.append((sent, clock_s))

    def sent_at(self, sent: int, now_s: float) -> float:
        """When a message sent at wall time ``sent`` (ns) was sent, on the node's clock.

        Under ``use_sim_time`` it is the time of the last ``/clock`` sent at or before it (a
        ``/clock`` sample sent just before the message but not delivered yet dates it one
        sample early). Never after ``now_s``; ``now_s`` itself when the send time is unknown,
        older than the kept ``/clock`` samples, or further back than :data:`MAX_DELAY_S`.

        Args:
            sent: The message's source timestamp, ns (0: unknown).
            now_s: The node's clock now, s.

        Returns:
            The send time on the node's clock, s.
        """
        if sent <= 0:
            return now_s
        if not self.sim_time:
            sent_s = sent * 1e-9
            return sent_s if now_s - MAX_DELAY_S <= sent_s <= now_s else now_s
        for clock_sent, clock_s in reversed(self._clocks):
            if clock_sent <= sent:
                return min(clock_s, now_s) if now_s - clock_s <= MAX_DELAY_S else now_s
        return now_s
