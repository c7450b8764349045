"""The tip series: planar tip poses over time, as every command reads and passes them.

``/tip_pose`` read from a bag (:func:`~lumpbeam_ros.bagio.series.read_tip_poses`), the window
the identifier analyses, the record a diagnosis fits and the trajectory a simulation
predicts all hold one :class:`TipSeries` or extend it (doc/interfaces.md, 'Frames, units
and time').
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
