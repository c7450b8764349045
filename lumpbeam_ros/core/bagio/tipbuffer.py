"""The live buffer of tip poses: the one rule for samples that arrive bad or out of turn.

A node receives poses one by one and cannot sort them as :func:`clean_tip_series` sorts a
bag's: :class:`TipBuffer` keeps the newest ``keep_s`` seconds in preallocated ring arrays
(a push is a few array stores, nothing grows while a node runs) and applies one rule to
every pose pushed:

- a NaN or inf stamp, z or pitch is dropped and counted ``non_finite``;
- a stamp equal to the newest one is dropped and counted ``duplicates``;
- a stamp before the newest one is dropped and counted ``out_of_order``;
- a stamp more than ``reset_jump_back_s`` before the newest one, or as far after it, is a
  *jump*, and one pose cannot tell a jump of the clock from a corrupt stamp: it is held
  until the next pose says which. A next pose nearer the held one than the newest stored
  confirms the jump (back: a bag looping; the buffer is emptied, counted in ``resets``, and
  the held pose starts it again; ahead: a pause in the stream); one nearer the newest stored
  says the held stamp was an outlier, dropped and counted ``out_of_order``. So a single
  stamp from the far future or past neither empties the buffer nor blinds it to the poses
  after it.

Nothing is dropped without a count, and the counts can be had for any stretch of the
buffer (:meth:`TipBuffer.between`): each stored pose remembers how many had been dropped
when it arrived, so a stretch's counts are what was dropped while its poses arrived. A
stretch with many drops (two streams interleaved, a looping replay feeding the same topic)
says so through :attr:`SampleCounts.untrusted`.

The identifier's window (:class:`~lumpbeam_ros.core.ident.window.SlidingWindow`) and the live
diagnosis (:class:`~lumpbeam_ros.core.diagnose.live.LiveBuffer`) both keep their poses here.
"""

from __future__ import annotations

import math

import numpy as np

from lumpbeam_ros.core.bagio.tipseries import SampleCounts, TipSeries

#: The ring's columns, in the order :meth:`TipBuffer._ordered` returns them.
_FLOATS = ('t', 'x', 'z', 'pitch')


class TipBuffer:
    """The newest ``keep_s`` seconds of tip poses, with the counts of those dropped.

    Args:
        keep_s: How much of the newest data a stretch may reach back, s.
        max_rate_hz: Highest pose rate the ring is sized for; faster input overwrites the
            oldest poses, so the buffer then covers less than ``keep_s``.
        reset_jump_back_s: A stamp this far before the newest one empties the buffer;
            smaller steps back are dropped as out of order.

    Raises:
        ValueError: A non-positive length, rate or jump.
    """

    def __init__(self, keep_s: float, max_rate_hz: float, reset_jump_back_s: float):
        if not (keep_s > 0.0 and max_rate_hz > 0.0 and reset_jump_back_s > 0.0):
            raise ValueError('buffer length, rate and jump must be positive')
        if not math.isfinite(keep_s * max_rate_hz):
            raise ValueError('buffer length and rate must be finite')
        self.keep_s = float(keep_s)
        self.reset_jump_back_s = float(reset_jump_back_s)
        self._capacity = int(math.ceil(keep_s * max_rate_hz)) + 1
        self._columns = {name: np.empty(self._capacity) for name in _FLOATS}
        # Drops counted before each stored pose arrived (non-finite; repeated or late).
        self._non_finite_before = np.zeros(self._capacity, dtype=np.int64)
        self._late_before = np.zeros(self._capacity, dtype=np.int64)
        self._head = 0
        self._size = 0
        self._last = -math.inf
        self._totals = {'non_finite': 0, 'duplicates': 0, 'out_of_order': 0, 'resets': 0}
        self._received = 0
        self._cleared_at = (0, 0)  # the drop totals when the buffer was last emptied
        # A pose whose stamp jumped, until the next pose says whether the clock did.
        self._held: tuple[float, float, float, float] | None = None

    def __len__(self) -> int:
        return self._size

    @property
    def newest_s(self) -> float:
        """Stamp of the newest pose (-inf when empty)."""
        return self._last

    @property
    def oldest_s(self) -> float:
        """Stamp of the oldest pose held (-inf when empty); it may be older than ``keep_s``."""
        if not self._size:
            return -math.inf
        return float(self._columns['t'][(self._head - self._size) % self._capacity])

    @property
    def t(self) -> np.ndarray:
        """Stamps of the newest ``keep_s`` seconds, oldest first (a copy), s."""
        return self.latest()[0].t

    @property
    def z(self) -> np.ndarray:
        """Vertical tip positions of the newest ``keep_s`` seconds, oldest first, m."""
        return self.latest()[0].z

    @property
    def counts(self) -> SampleCounts:
        """Every pose pushed since the buffer was made, and what became of it (once decided)."""
        return SampleCounts(
            # A held pose is counted once the next pose decides it.
            received=self._received - self.holding,
            non_finite=self._totals['non_finite'],
            duplicates=self._totals['duplicates'],
            out_of_order=self._totals['out_of_order'],
            resets=self._totals['resets'],
        )

    def clear(self) -> None:
        """Empties the buffer; the counts since it was made are kept."""
        self._head = 0
        self._size = 0
        self._last = -math.inf
        self._held = None
        self._cleared_at = self._drops()

    @property
    def holding(self) -> bool:
        """Whether a pose whose stamp jumped waits for the next one to confirm it."""
        return self._held is not None

    def push(self, stamp: float, z: float, pitch: float = 0.0, x: float = math.nan) -> bool:
        """Adds one tip pose, or counts why not (the module's rule).

        Args:
            stamp: Header stamp, s.
            z: Vertical tip position, m.
            pitch: Tip pitch, rad.
            x: Tip position along the beam, m (NaN when not measured). No estimator uses
                it, so a non-finite x does not drop the pose.

        Returns:
            Whether the pose was stored (``False`` for one held until the next pose).
        """
        self._received += 1
        if not (math.isfinite(stamp) and math.isfinite(z) and math.isfinite(pitch)):
            self._totals['non_finite'] += 1
            return False
        held, self._held = self._held, None
        if held is not None:
            if abs(stamp - held[0]) < abs(stamp - self._last):
                if held[0] < self._last:
                    self._totals['resets'] += 1
                    self.clear()
                self._store(*held)
            else:
                self._totals['out_of_order'] += 1
        if abs(stamp - self._last) > self.reset_jump_back_s and self._size:
            self._held = (stamp, x, z, pitch)
            return False
        if stamp == self._last:
            self._totals['duplicates'] += 1
            return False
        if stamp < self._last:
            self._totals['out_of_order'] += 1
            return False
        self._store(stamp, x, z, pitch)
        return True

    def _store(self, stamp: float, x: float, z: float, pitch: float) -> None:
        i = self._head
        for name, value in zip(_FLOATS, (stamp, x, z, pitch), strict=True):
            self._columns[name][i] = value
        self._non_finite_before[i], self._late_before[i] = self._drops()
        self._head = (i + 1) % self._capacity
        self._size = min(self._size + 1, self._capacity)
        self._last = stamp

    def latest(self) -> tuple[TipSeries, SampleCounts]:
        """The poses of the newest ``keep_s`` seconds, oldest first, and their counts."""
        return self.between(self._last - self.keep_s, self._last)

    def between(self, start: float, end: float) -> tuple[TipSeries, SampleCounts]:
        """The poses held with ``start <= t <= end``, and what was dropped among them.

        Args:
            start: From, s (no earlier than ``keep_s`` before the newest pose).
            end: To, s (inclusive).

        Returns:
            Copies of the poses (``frame_id`` ``beam_base``) and their counts: the poses
            dropped while these arrived (from the first one's arrival to the next pose's
            after the last one); for no pose, those dropped since the buffer was emptied.
        """
        t, x, z, pitch, non_finite_before, late_before = self._ordered()
        start = max(start, self._last - self.keep_s)
        first = int(np.searchsorted(t, start, side='left'))
        stop = int(np.searchsorted(t, end, side='right'))
        poses = TipSeries(t[first:stop], x[first:stop], z[first:stop], pitch[first:stop])
        now = self._drops()
        if stop <= first:
            begin = self._cleared_at
        else:
            begin = (int(non_finite_before[first]), int(late_before[first]))
        until = (int(non_finite_before[stop]), int(late_before[stop])) if stop < t.size else now
        non_finite, late = until[0] - begin[0], until[1] - begin[1]
        counts = SampleCounts(
            received=len(poses) + non_finite + late, non_finite=non_finite, duplicates=late
        )
        return poses, counts

    def _drops(self) -> tuple[int, int]:
        """Poses dropped so far: non-finite, and repeated or late."""
        c = self._totals
        return c['non_finite'], c['duplicates'] + c['out_of_order']

    def _ordered(self) -> tuple[np.ndarray, ...]:
        """The ring's columns oldest first (copies): t, x, z, pitch and the drop counters."""
        arrays: list[np.ndarray] = [self._columns[name] for name in _FLOATS]
        arrays += [self._non_finite_before, self._late_before]
        n = self._size
        start = (self._head - n) % self._capacity
        if start + n <= self._capacity:
            return tuple(a[start : start + n].copy() for a in arrays)
        return tuple(np.concatenate([a[start:], a[: self._head]]) for a in arrays)
