"""The tip trajectory a simulation produces (and a measurement is compared with)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class TipTrajectory:
    """Tip pose samples in frame ``beam_base`` (doc/interfaces.md, 'Frames, units and time').

    Attributes:
        t: Sample times, s, increasing.
        x: Tip position along the undeformed beam, m.
        z: Vertical tip position, m (negative when the beam sags).
        pitch: Tip slope about +y, rad (positive when the tip points downward).
        load_kg: Mass hanging at the tip at each sample, kg.
        q: Absolute segment angles at each sample (n_samples x n_s), rad; may be empty.
    """

    t: np.ndarray
    x: np.ndarray
    z: np.ndarray
    pitch: np.ndarray
    load_kg: np.ndarray
    q: np.ndarray | None = None

    def __len__(self) -> int:
        return int(self.t.size)

    def slice_time(self, start: float, end: float) -> TipTrajectory:
        """Returns the samples with ``start <= t < end``."""
        keep = (self.t >= start) & (self.t < end)
        return TipTrajectory(
            self.t[keep],
            self.x[keep],
            self.z[keep],
            self.pitch[keep],
            self.load_kg[keep],
            None if self.q is None else self.q[keep],
        )
