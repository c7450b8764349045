"""The live identifier's sliding window of tip poses and ``/tip_load`` readings.

The poses are kept in a :class:`~lumpbeam_ros.core.bagio.tipbuffer.TipBuffer` (the one live
buffer, with its one rule for bad samples), the readings in two short lists. A sample that
would break the window's order is dropped and counted, never raised: a live node logs the
counts instead, and an identification of a window with many drops is at best a WARN.
"""

from __future__ import annotations

import bisect
import math
from dataclasses import replace

import numpy as np

from lumpbeam_ros.core.bagio.tipbuffer import TipBuffer
from lumpbeam_ros.core.bagio.tipseries import LoadSeries, SampleCounts
from lumpbeam_ros.core.ident.samples import PoseWindow
from lumpbeam_ros.core.ident.settings import IdentifierConfig


class SlidingWindow:
    """The last ``length_s`` seconds of tip poses, for :func:`~lumpbeam_ros.core.ident.identify`.

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
        self,
        length_s: float = IdentifierConfig.window_s,
        max_rate_hz: float = IdentifierConfig.max_rate_hz,
        reset_jump_back_s: float = IdentifierConfig.reset_jump_back_s,
    ):
        if not (length_s > 0.0 and max_rate_hz > 0.0 and reset_jump_back_s > 0.0):
            raise ValueError('window length, rate and jump must be positive')
        self.length_s = float(length_s)
        self.reset_jump_back_s = float(reset_jump_back_s)
        self.poses = TipBuffer(length_s, max_rate_hz, reset_jump_back_s)
        self._load_t: list[float] = []
        self._load_kg: list[float] = []
        self._loads_rejected = 0

    @classmethod
    def from_config(cls, config: IdentifierConfig) -> SlidingWindow:
        """A window sized by ``window.length_s``, ``window.max_rate_hz`` and the jump."""
        return cls(config.window_s, config.max_rate_hz, config.reset_jump_back_s)

    def __len__(self) -> int:
        return len(self.poses)

    @property
    def counts(self) -> SampleCounts:
        """Every sample pushed since the window was made, and what became of it."""
        return replace(self.poses.counts, loads_rejected=self._loads_rejected)

    @property
    def newest_s(self) -> float:
        """Stamp of the newest pose (-inf when empty)."""
        return self.poses.newest_s

    def clear(self) -> None:
        """Empties the window (poses and loads); the counts are kept."""
        self.poses.clear()
        self._load_t.clear()
        self._load_kg.clear()

    def push(self, stamp: float, z: float, pitch: float = 0.0, x: float = math.nan) -> bool:
        """Adds one tip pose (:meth:`~lumpbeam_ros.core.bagio.tipbuffer.TipBuffer.push`).

        A clock that jumps back empties the window, but the mass hanging does not change
        because the clock jumped: the last ``/tip_load`` reading is kept, restamped.

        Args:
            stamp: Header stamp, s.
            z: Vertical tip position, m.
            pitch: Tip pitch, rad.
            x: Tip position along the beam, m (NaN when not measured).

        Returns:
            Whether the sample was stored.
        """
        resets = self.poses.counts.resets
        stored = self.poses.push(stamp, z, pitch, x)
        if self.poses.counts.resets != resets:
            kept = self._load_kg[-1:]
            self._load_t[:] = [self.poses.oldest_s for _ in kept]
            self._load_kg[:] = kept
        return stored

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
            self._loads_rejected += 1
            return False
        if stamp < latest - self.reset_jump_back_s:
            self._load_t.clear()
            self._load_kg.clear()
        elif stamp == latest:
            # Two readings within one pose period: the later one holds.
            self._load_kg[-1] = float(kg)
            return True
        elif stamp < latest:
            self._loads_rejected += 1
            return False
        self._load_t.append(float(stamp))
        self._load_kg.append(float(kg))
        self._prune_loads(max(stamp, self.newest_s) - self.length_s)
        return True

    def push_load_on_arrival(self, kg: float, clock_s: float) -> tuple[bool, float]:
        """Adds a ``/tip_load`` reading that carries no stamp (``Float64``).

        It is stamped with the newest pose's stamp (the data's own clock; the node's clock
        may be another one, or run ahead of a backlog of poses), or ``clock_s`` before any
        pose. The stamp is only a hint: the release itself is timed from the poses
        (:func:`~lumpbeam_ros.core.ident.release.detect_release`).

        Args:
            kg: Mass at the tip, kg.
            clock_s: The receiver's clock now, s.

        Returns:
            Whether the reading was stored, and the stamp it was given.
        """
        newest = self.newest_s
        stamp = newest if math.isfinite(newest) else clock_s
        return self.push_load(stamp, kg), stamp

    def snapshot(self) -> PoseWindow:
        """The poses of the last ``length_s`` seconds, oldest first, with their loads.

        Returns:
            A :class:`~lumpbeam_ros.core.ident.samples.PoseWindow` holding copies; its counts
            are the poses dropped while the window's poses arrived.
        """
        poses, counts = self.poses.latest()
        self._prune_loads(self.newest_s - self.length_s)
        loads = LoadSeries(np.asarray(self._load_t), np.asarray(self._load_kg))
        return PoseWindow(poses, loads, counts)

    def _prune_loads(self, start: float) -> None:
        """Drops readings before ``start`` but the last of them: it gives the load then."""
        keep_from = bisect.bisect_left(self._load_t, start) - 1
        if keep_from > 0:
            del self._load_t[:keep_from]
            del self._load_kg[:keep_from]
