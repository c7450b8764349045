"""The tip trajectory a simulation produces (and a measurement is compared with)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lumpbeam_ros.core.bagio.tipseries import TipSeries


@dataclass(frozen=True)
class TipTrajectory(TipSeries):
    """A model's tip series in frame ``beam_base``, with the load and the segment angles.

    The pose fields are those of :class:`~lumpbeam_ros.core.bagio.tipseries.TipSeries`, so a
    prediction goes wherever a measured series does; :meth:`~TipSeries.between` cuts the
    load and angles with the poses.

    Attributes:
        load_kg: Mass hanging at the tip at each sample, kg.
        q: Absolute segment angles at each sample (n_samples x n_s), rad; may be empty.
    """

    load_kg: np.ndarray
    q: np.ndarray | None = None
