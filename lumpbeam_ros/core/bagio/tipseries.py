"""The tip series: planar tip poses over time, as every command reads and passes them.

``/tip_pose`` read from a bag (:func:`~lumpbeam_ros.core.bagio.series.read_tip_poses`), the window
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

from lumpbeam_ros.base.interface import BASE_FRAME

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


#: A window with more than this fraction of its poses dropped (non-finite, repeated or out
#: of order) is not trusted: its estimate is at best a WARN. Interleaved streams (two
#: replays feeding one node) drop about half; a healthy camera drops none.
MAX_DROPPED_FRACTION = 0.05


@dataclass(frozen=True)
class SampleCounts:
    """What became of the tip poses given: the one count of bad samples, offline and live.

    :func:`clean_tip_series` fills it for a bag's poses (it sorts, so nothing is out of
    order there); :class:`~lumpbeam_ros.core.bagio.tipbuffer.TipBuffer` for the poses a live node
    received, which it cannot sort.

    Attributes:
        received: Samples given.
        non_finite: Samples dropped for a NaN or inf stamp, z or pitch.
        duplicates: Samples dropped because an earlier one had the same stamp.
        reordered: Whether the stamps had to be sorted.
        out_of_order: Samples dropped for a stamp before the newest one (a live buffer).
        resets: Times a live buffer was emptied because the clock jumped back.
        loads_rejected: ``/tip_load`` readings rejected (non-finite, negative or stale).
        outliers: Samples dropped as isolated outliers of the motion
            (:mod:`~lumpbeam_ros.core.ident.outliers`).
    """

    received: int = 0
    non_finite: int = 0
    duplicates: int = 0
    reordered: bool = False
    out_of_order: int = 0
    resets: int = 0
    loads_rejected: int = 0
    outliers: int = 0

    @property
    def dropped(self) -> int:
        """Samples dropped, whatever the reason."""
        return self.non_finite + self.duplicates + self.out_of_order + self.outliers

    @property
    def kept(self) -> int:
        """Samples left after validation."""
        return self.received - self.dropped

    @property
    def n_samples(self) -> int:
        """Samples kept (the ``n_samples`` key of an identification)."""
        return self.kept

    @property
    def n_rejected(self) -> int:
        """Samples dropped (the ``n_rejected`` key of an identification)."""
        return self.dropped

    @property
    def dropped_fraction(self) -> float:
        """The share of the samples given that was dropped (0 for none given)."""
        return self.dropped / self.received if self.received else 0.0

    @property
    def untrusted(self) -> bool:
        """Whether more than :data:`MAX_DROPPED_FRACTION` of the samples was dropped."""
        return self.dropped_fraction > MAX_DROPPED_FRACTION

    def then(self, later: SampleCounts) -> SampleCounts:
        """These counts followed by those of a validation of the samples these kept.

        Args:
            later: What a second validation (given ``self.kept`` samples) dropped.

        Returns:
            The drops of both, out of the samples first given.
        """
        return SampleCounts(
            received=self.received,
            non_finite=self.non_finite + later.non_finite,
            duplicates=self.duplicates + later.duplicates,
            reordered=self.reordered or later.reordered,
            out_of_order=self.out_of_order + later.out_of_order,
            resets=self.resets + later.resets,
            loads_rejected=self.loads_rejected + later.loads_rejected,
            outliers=self.outliers + later.outliers,
        )

    def note(self) -> str:
        """What validation did, in one line (``''`` when it changed nothing)."""
        parts = []
        if self.non_finite:
            parts.append(f'{self.non_finite} with a NaN or inf stamp, position or orientation')
        repeated = self.duplicates + self.out_of_order
        if repeated:
            parts.append(f'{repeated} with a repeated or out-of-order stamp')
        if self.outliers:
            parts.append(f'{self.outliers} isolated outliers')
        notes = []
        if parts:
            notes.append(f'dropped {self.dropped} of {self.received} poses ({"; ".join(parts)})')
        if self.reordered:
            notes.append('stamps out of order: sorted')
        return '; '.join(notes)


@dataclass(frozen=True)
class LoadSeries:
    """``/tip_load`` readings: the mass hanging at the tip from each stamp on.

    A bag's topic (:func:`~lumpbeam_ros.core.bagio.series.read_load_events`, stamped by log
    time), the readings of an identifier's window, a comparison's loads: one type.

    Attributes:
        t: Stamps, s, increasing.
        kg: Mass at the tip from that stamp on, kg.
    """

    t: np.ndarray = field(default_factory=lambda: np.empty(0))
    kg: np.ndarray = field(default_factory=lambda: np.empty(0))

    def __len__(self) -> int:
        return int(self.t.size)

    def changes(self) -> LoadSeries:
        """The first reading and every reading whose value differs from the one before."""
        if self.t.size == 0:
            return self
        keep = np.concatenate([[True], self.kg[1:] != self.kg[:-1]])
        return LoadSeries(self.t[keep], self.kg[keep])

    def between(self, start: float, end: float) -> LoadSeries:
        """The readings from ``start`` to ``end``, with the last one before ``start``.

        That first reading gives the load at ``start``.
        """
        first = max(int(np.searchsorted(self.t, start, side='right')) - 1, 0)
        last = int(np.searchsorted(self.t, end, side='right'))
        return LoadSeries(self.t[first:last], self.kg[first:last])


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
