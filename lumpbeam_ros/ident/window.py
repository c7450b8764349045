"""The live identifier's sliding window of tip poses and ``/tip_load`` readings.

Poses go into preallocated ring buffers, so a push is a few array stores and a snapshot two
slices; nothing grows while the node runs. A sample that would break the window's order is
rejected and counted, never raised: a live node logs the counts instead.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import dataclass

import numpy as np

from lumpbeam_ros.bagio.tipseries import SampleCounts, TipSeries
from lumpbeam_ros.ident.samples import LoadReadings, PoseWindow
from lumpbeam_ros.ident.settings import IdentifierConfig


@dataclass(frozen=True)
class WindowCounts:
    """What the window did with the samples pushed since it was made.

    Attributes:
        accepted: Poses stored.
        non_finite: Poses rejected for a NaN or inf stamp, z or pitch.
        out_of_order: Poses rejected for a stamp before the newest one (within the jump).
        duplicates: Poses rejected for repeating the newest stamp.
        resets: Times the window was emptied because the clock jumped back.
        loads_rejected: ``/tip_load`` readings rejected (non-finite, negative or stale).
    """

    accepted: int = 0
    non_finite: int = 0
    out_of_order: int = 0
    duplicates: int = 0
    resets: int = 0
    loads_rejected: int = 0


class SlidingWindow:
    """The last ``length_s`` seconds of tip poses, for :func:`~lumpbeam_ros.ident.identify`.

    Example (in a node's callbacks)::

        window = SlidingWindow.from_config(config)
        window.push(stamp, z, pitch, x)       # each /tip_pose
        window.push_load(stamp, kg)           # each /tip_load
        result = identify(window.snapshot(), beam, config)   # on the publish timer

    Args:
        length_s: Window length, s.
        max_rate_hz: Highest pose rate the buffer is sized for; faster input overwrites the
            oldest samples, so the window then covers less than ``length_s``.
        reset_jump_back_s: A stamp this far before the newest one empties the window (a bag
            looping); smaller steps back are rejected as out of order.

    Raises:
        ValueError: A non-positive length, rate or jump.
    """

    def __init__(
        self, length_s: float = 10.0, max_rate_hz: float = 400.0, reset_jump_back_s: float = 1.0
    ):
        if not (length_s > 0.0 and max_rate_hz > 0.0 and reset_jump_back_s > 0.0):
            raise ValueError('window length, rate and jump must be positive')
        self.length_s = float(length_s)
        self.reset_jump_back_s = float(reset_jump_back_s)
        self._capacity = int(math.ceil(length_s * max_rate_hz)) + 1
        self._t = np.empty(self._capacity)
        self._x = np.empty(self._capacity)
        self._z = np.empty(self._capacity)
        self._pitch = np.empty(self._capacity)
        self._head = 0
        self._size = 0
        self._last = -math.inf
        self._load_t: list[float] = []
        self._load_kg: list[float] = []
        self._counts = {name: 0 for name in WindowCounts.__dataclass_fields__}

    @classmethod
    def from_config(cls, config: IdentifierConfig) -> SlidingWindow:
        """A window sized by ``window.length_s``, ``window.max_rate_hz`` and the jump."""
        return cls(config.window_s, config.max_rate_hz, config.reset_jump_back_s)

    def __len__(self) -> int:
        return self._size

    @property
    def counts(self) -> WindowCounts:
        """What happened to the samples pushed so far."""
        return WindowCounts(**self._counts)

    @property
    def newest_s(self) -> float:
        """Stamp of the newest pose (-inf when empty)."""
        return self._last

    def clear(self) -> None:
        """Empties the window (poses and loads); the counts are kept."""
        self._head = 0
        self._size = 0
        self._last = -math.inf
        self._load_t.clear()
        self._load_kg.clear()

    def push(self, stamp: float, z: float, pitch: float = 0.0, x: float = math.nan) -> bool:
        """Adds one tip pose.

        Args:
            stamp: Header stamp, s.
            z: Vertical tip position, m.
            pitch: Tip pitch, rad.
            x: Tip position along the beam, m (NaN when not measured). The estimators do not
                use it, so a non-finite x does not reject the pose.

        Returns:
            Whether the sample was stored.
        """
        if not (math.isfinite(stamp) and math.isfinite(z) and math.isfinite(pitch)):
            self._counts['non_finite'] += 1
            return False
        if stamp <= self._last:
            if stamp < self._last - self.reset_jump_back_s:
                self._counts['resets'] += 1
                # The mass hanging does not change because the clock jumped: keep it.
                kept = self._load_kg[-1:] if self._load_kg else []
                self.clear()
                self._load_t.extend(stamp for _ in kept)
                self._load_kg.extend(kept)
            elif stamp == self._last:
                self._counts['duplicates'] += 1
                return False
            else:
                self._counts['out_of_order'] += 1
                return False
        i = self._head
        self._t[i] = stamp
        self._x[i] = x
        self._z[i] = z
        self._pitch[i] = pitch
        self._head = (i + 1) % self._capacity
        self._size = min(self._size + 1, self._capacity)
        self._last = stamp
        self._counts['accepted'] += 1
        return True

    def push_load(self, stamp: float, kg: float) -> bool:
        """Adds one ``/tip_load`` reading (mass hanging at the tip from ``stamp`` on).

        Args:
            stamp: Stamp of the reading, s.
            kg: Mass at the tip, kg.

        Returns:
            Whether the reading was stored.
        """
        latest = self._load_t[-1] if self._load_t else -math.inf
        if not (math.isfinite(stamp) and math.isfinite(kg) and kg >= 0.0):
            self._counts['loads_rejected'] += 1
            return False
        if stamp < latest - self.reset_jump_back_s:
            self._load_t.clear()
            self._load_kg.clear()
        elif stamp == latest:
            # Two readings within one pose period: the later one holds.
            self._load_kg[-1] = float(kg)
            return True
        elif stamp < latest:
            self._counts['loads_rejected'] += 1
            return False
        self._load_t.append(float(stamp))
        self._load_kg.append(float(kg))
        self._prune_loads(max(stamp, self._last) - self.length_s)
        return True

    def push_load_on_arrival(self, kg: float, clock_s: float) -> tuple[bool, float]:
        """Adds a ``/tip_load`` reading that carries no stamp (``Float64``).

        It is stamped with the newest pose's stamp (the data's own clock; the node's clock
        may be another one, or run ahead of a backlog of poses), or ``clock_s`` before any
        pose. The stamp is only a hint: the release itself is timed from the poses
        (:func:`~lumpbeam_ros.ident.release.detect_release`).

        Args:
            kg: Mass at the tip, kg.
            clock_s: The receiver's clock now, s.

        Returns:
            Whether the reading was stored, and the stamp it was given.
        """
        stamp = self._last if math.isfinite(self._last) else clock_s
        return self.push_load(stamp, kg), stamp

    def snapshot(self) -> PoseWindow:
        """The poses of the last ``length_s`` seconds, oldest first, with their loads.

        Returns:
            A :class:`~lumpbeam_ros.ident.samples.PoseWindow` holding copies; its counts
            are the window's rejections since it was made.
        """
        n = self._size
        start = (self._head - n) % self._capacity
        if start + n <= self._capacity:
            part = slice(start, start + n)
            t, x, z, pitch = (a[part].copy() for a in (self._t, self._x, self._z, self._pitch))
        else:
            first, second = slice(start, self._capacity), slice(0, self._head)
            t, x, z, pitch = (
                np.concatenate([a[first], a[second]])
                for a in (self._t, self._x, self._z, self._pitch)
            )
        cut = int(np.searchsorted(t, self._last - self.length_s, side='left')) if n else 0
        poses = TipSeries(t, x, z, pitch).select(slice(cut, None))
        self._prune_loads(self._last - self.length_s)
        loads = LoadReadings(np.asarray(self._load_t), np.asarray(self._load_kg))
        c = self._counts
        counts = SampleCounts(
            received=len(poses) + c['non_finite'] + c['out_of_order'] + c['duplicates'],
            non_finite=c['non_finite'],
            duplicates=c['out_of_order'] + c['duplicates'],
        )
        return PoseWindow(poses, loads, counts)

    def _prune_loads(self, start: float) -> None:
        """Drops readings before ``start`` but the last of them: it gives the load then."""
        keep_from = bisect.bisect_left(self._load_t, start) - 1
        if keep_from > 0:
            del self._load_t[:keep_from]
            del self._load_kg[:keep_from]
