"""The tip series: planar tip poses over time, as every command reads and passes them.

``/tip_pose`` read from a bag (:func:`~lumpbeam_ros.bagio.series.read_tip_poses`), the window
the identifier analyses, the record a diagnosis fits and the trajectory a simulation
predicts all hold one :class:`TipSeries` or extend it (doc/interfaces.md, 'Frames, units
and time'). Raw poses become strictly increasing, finite ones one way,
:func:`clean_tip_series`, which says what it dropped in a :class:`SampleCounts`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any, TypeVar

import numpy as np

from lumpbeam_ros.interface import BASE_FRAME

_Series = TypeVar('_Series', bound='TipSeries')


@dataclass(frozen=True)
class TipSeries:
    """Tip poses in one frame, one sample per stamp.

    An extension (a model's trajectory) may add per-sample arrays; :meth:`select` and
    :meth:`between` cut every field that holds one entry per stamp.

    Attributes:
        t: Stamps, s (sorted when read from a bag).
        x: Tip position along the undeformed beam, m (NaN where not measured).
        z: Vertical tip position, m (negative when the beam sags).
        pitch: Tip slope about +y, rad (positive when the tip points downward; NaN where
            not measured).
        frame_id: The frame of the poses (``''`` for a topic without messages).
    """

    t: np.ndarray
    x: np.ndarray
    z: np.ndarray
    pitch: np.ndarray
    frame_id: str = field(default=BASE_FRAME, kw_only=True)

    @classmethod
    def vertical(
        cls, t: np.ndarray, z: np.ndarray, pitch: np.ndarray, frame_id: str = BASE_FRAME
    ) -> TipSeries:
        """A series of the vertical motion only: ``x`` is not known (NaN).

        Args:
            t: Stamps, s.
            z: Vertical tip positions, m.
            pitch: Tip slopes, rad.
            frame_id: Their frame.

        Returns:
            The series.
        """
        return cls(t, np.full(np.shape(t), np.nan), z, pitch, frame_id=frame_id)

    def __len__(self) -> int:
        return int(self.t.size)

    @property
    def start_s(self) -> float:
        """First stamp (NaN when empty)."""
        return float(self.t[0]) if self.t.size else float('nan')

    @property
    def end_s(self) -> float:
        """Last stamp (NaN when empty)."""
        return float(self.t[-1]) if self.t.size else float('nan')

    def select(self: _Series, keep: np.ndarray | slice) -> _Series:
        """The samples a boolean mask, an index array or a slice picks.

        Args:
            keep: Applied to every per-sample array (``t``, ``x``, ``z``, ``pitch`` and an
                extension's own).

        Returns:
            A series of the same type.
        """
        n = self.t.size
        picked: dict[str, Any] = {
            f.name: value[keep]
            for f in dataclasses.fields(self)
            if isinstance(value := getattr(self, f.name), np.ndarray) and value.shape[:1] == (n,)
        }
        return dataclasses.replace(self, **picked)

    def between(self: _Series, start: float, end: float) -> _Series:
        """The samples with ``start <= t < end``."""
        return self.select((self.t >= start) & (self.t < end))


class HoldsTipSeries:
    """The columns of the tip series a record type holds as ``poses``, read through it."""

    poses: TipSeries

    @property
    def t(self) -> np.ndarray:
        """Stamps, s."""
        return self.poses.t

    @property
    def z(self) -> np.ndarray:
        """Vertical tip position, m."""
        return self.poses.z

    @property
    def pitch(self) -> np.ndarray:
        """Tip slope about +y, rad."""
        return self.poses.pitch

    def __len__(self) -> int:
        return len(self.poses)

    @property
    def start_s(self) -> float:
        """First stamp (NaN when empty)."""
        return self.poses.start_s

    @property
    def end_s(self) -> float:
        """Last stamp (NaN when empty)."""
        return self.poses.end_s


@dataclass(frozen=True)
class SampleCounts:
    """What :func:`clean_tip_series` removed from the poses given.

    Attributes:
        received: Samples given.
        non_finite: Samples dropped for a NaN or inf stamp, z or pitch.
        duplicates: Samples dropped because an earlier one had the same stamp.
        reordered: Whether the stamps had to be sorted.
    """

    received: int = 0
    non_finite: int = 0
    duplicates: int = 0
    reordered: bool = False

    @property
    def kept(self) -> int:
        """Samples left after validation."""
        return self.received - self.non_finite - self.duplicates

    def note(self) -> str:
        """What validation did, in one line (``''`` when it changed nothing)."""
        parts = []
        if self.non_finite:
            parts.append(f'{self.non_finite} with a NaN or inf stamp, position or orientation')
        if self.duplicates:
            parts.append(f'{self.duplicates} with a repeated or out-of-order stamp')
        notes = []
        if parts:
            dropped = self.non_finite + self.duplicates
            notes.append(f'dropped {dropped} of {self.received} poses ({"; ".join(parts)})')
        if self.reordered:
            notes.append('stamps out of order: sorted')
        return '; '.join(notes)


def clean_tip_series(
    poses: _Series, *, pitch_required: bool = True
) -> tuple[_Series, SampleCounts]:
    """Strictly increasing, finite tip poses, and what it took to get them.

    Non-finite samples are dropped, stamps sorted, and of several samples with one stamp the
    first is kept. Gaps are left as they are: the estimators work on uneven stamps. ``x`` is
    carried along, not checked (no estimator uses it).

    Args:
        poses: The raw series (a bag's, a live buffer's, a simulation's).
        pitch_required: Whether a NaN or inf pitch drops the sample (``False`` for a sensor
            that measures no pitch).

    Returns:
        The cleaned series (of the type given) and the counts of what was removed.
    """
    received = len(poses)
    keep = np.isfinite(poses.t) & np.isfinite(poses.z)
    if pitch_required:
        keep &= np.isfinite(poses.pitch)
    non_finite = received - int(np.count_nonzero(keep))
    poses = poses.select(keep)
    reordered = bool(np.any(np.diff(poses.t) < 0.0))
    if reordered:
        poses = poses.select(np.argsort(poses.t, kind='stable'))
    first = np.ones(len(poses), dtype=bool)
    first[1:] = np.diff(poses.t) > 0.0
    duplicates = int(len(poses) - np.count_nonzero(first))
    if duplicates:
        poses = poses.select(first)
    return poses, SampleCounts(received, non_finite, duplicates, reordered)
