"""Measured against predicted tip motion (as the paper's Figs. B.8-B.10) and the residual.

:func:`prediction_residual` aligns ``/tip_pose_predicted`` with ``/tip_pose`` by header stamp
(the simulator's samples are linearly interpolated to each measured stamp; with both at 180 Hz
on the same grid the interpolation is exact); :func:`plot_measured_vs_predicted` draws both
and the residual.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lumpbeam_ros.apps.plots.files import save_figure
from lumpbeam_ros.base.errors import LumpbeamError


@dataclass(frozen=True)
class Residual:
    """A measurement and a prediction on the measurement's stamps.

    Attributes:
        t: Measured stamps inside the prediction's span, s.
        measured: Measured vertical tip position, m.
        predicted: Predicted vertical tip position at ``t``, m.
    """

    t: np.ndarray
    measured: np.ndarray
    predicted: np.ndarray

    @property
    def residual(self) -> np.ndarray:
        """Measured minus predicted, m."""
        return np.asarray(self.measured - self.predicted)

    def rms(self, start: float = -np.inf, end: float = np.inf) -> float:
        """RMS of the residual over ``start <= t < end``, m (NaN when no sample)."""
        keep = (self.t >= start) & (self.t < end)
        return float(np.sqrt(np.mean(self.residual[keep] ** 2))) if keep.any() else np.nan


def prediction_residual(
    t_measured: np.ndarray,
    z_measured: np.ndarray,
    t_predicted: np.ndarray,
    z_predicted: np.ndarray,
) -> Residual:
    """Aligns a prediction with a measurement by stamp.

    Args:
        t_measured: Measured stamps, s, increasing.
        z_measured: Measured z, m.
        t_predicted: Predicted stamps, s, increasing.
        z_predicted: Predicted z, m.

    Returns:
        The measured samples inside the predicted span, with the prediction at their stamps.

    Raises:
        LumpbeamError: Arrays of different lengths, or the two series do not overlap in time.
    """
    t_m, z_m = np.asarray(t_measured, float), np.asarray(z_measured, float)
    t_p, z_p = np.asarray(t_predicted, float), np.asarray(z_predicted, float)
    if t_m.shape != z_m.shape or t_p.shape != z_p.shape:
        raise LumpbeamError('stamps and positions must have the same length')
    if t_p.size < 2:
        raise LumpbeamError(f'the prediction has {t_p.size} samples; need at least 2')
    inside = (t_m >= t_p[0]) & (t_m <= t_p[-1])
    if not inside.any():
        raise LumpbeamError(
            f'measurement ({t_m[0] if t_m.size else "empty"}..) and prediction '
            f'({t_p[0]:.3f}..{t_p[-1]:.3f} s) do not overlap in time'
        )
    t = t_m[inside]
    return Residual(t, z_m[inside], np.interp(t, t_p, z_p))


def plot_measured_vs_predicted(
    residual: Residual,
    path: str | Path,
    *,
    span: tuple[float, float] | None = None,
    release_time_s: float | None = None,
    title: str = 'Tip: measured (/tip_pose) and predicted (/tip_pose_predicted)',
    labels: tuple[str, str] = ('measured /tip_pose', 'predicted /tip_pose_predicted'),
) -> Path:
    """Draws the measured and predicted tip z over time, and their difference below.

    The difference is drawn in micrometres when it is below a tenth of a millimetre RMS.

    Args:
        residual: The aligned series (:func:`prediction_residual`).
        path: Output image (PNG, or any format matplotlib writes); its folder is created.
        span: ``(start, end)`` in s to show; all when ``None``.
        release_time_s: Marks the load's release, if given.
        title: Figure title.
        labels: Legend entries of the two series.

    Returns:
        The written path.

    Raises:
        LumpbeamError: Nothing to draw in ``span``, or the file cannot be written.
    """
    import matplotlib

    matplotlib.use('Agg')
    from matplotlib import pyplot as plt

    t, keep = residual.t, np.ones(residual.t.size, bool)
    if span is not None:
        keep = (t >= span[0]) & (t <= span[1])
    if not keep.any():
        raise LumpbeamError(f'no aligned samples in {span}')
    figure, (top, bottom) = plt.subplots(
        2, 1, sharex=True, figsize=(9, 6), gridspec_kw={'height_ratios': [2, 1]}
    )
    try:
        top.plot(t[keep], residual.measured[keep] * 1e3, lw=0.8, label=labels[0])
        top.plot(t[keep], residual.predicted[keep] * 1e3, lw=0.8, ls='--', label=labels[1])
        top.set_ylabel('tip z (mm)')
        figure.suptitle(title)
        rms = float(np.sqrt(np.mean(residual.residual[keep] ** 2)))
        scale, unit = (1e6, 'um') if rms < 1e-4 else (1e3, 'mm')
        bottom.plot(t[keep], residual.residual[keep] * scale, lw=0.6, color='tab:red')
        bottom.set_ylabel(f'difference ({unit})')
        bottom.set_xlabel('time (s, header stamp)')
        for axis in (top, bottom):
            axis.grid(alpha=0.3)
            if release_time_s is not None and t[keep][0] <= release_time_s <= t[keep][-1]:
                axis.axvline(release_time_s, color='gray', lw=0.8, ls=':')
        # Above the axes: the oscillation fills the whole plot area.
        top.legend(loc='lower center', bbox_to_anchor=(0.5, 1.0), ncol=2, frameon=False)
        bottom.text(
            0.01, 0.9, f'RMS {rms * scale:.3f} {unit}', transform=bottom.transAxes, va='top'
        )
        return save_figure(figure, path, dpi=120, bbox_inches='tight')
    finally:
        plt.close(figure)
