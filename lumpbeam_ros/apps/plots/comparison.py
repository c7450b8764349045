"""The camera against the reference sensor, as the paper's Fig. B.8."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use('Agg')

import matplotlib.pyplot as plt  # noqa: E402  (the backend is chosen first)

from lumpbeam_ros.apps.plots.files import save_figure  # noqa: E402
from lumpbeam_ros.core.compare.comparison import Comparison  # noqa: E402

FILE_NAME = 'compare.png'


def plot_comparison(comparison: Comparison, folder: str | Path) -> Path:
    """Draws both vertical tip traces on the camera clock and their difference.

    Args:
        comparison: The result of :func:`~lumpbeam_ros.core.compare.compare_sensors`.
        folder: Where to write :data:`FILE_NAME` (created when missing).

    Returns:
        The image file written.

    Raises:
        LumpbeamError: The folder or file cannot be written.
    """
    folder = Path(folder)
    path = folder / FILE_NAME
    offset = comparison.aligned.alignment.offset_s
    figure, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(9.0, 6.0))
    try:
        top.plot(
            comparison.reference_t,
            comparison.reference_points[:, 2] * 1e3,
            color='tab:orange',
            lw=1.6,
            label=f'tracker ({comparison.aligned.reference.track.source}, in beam_base)',
        )
        top.plot(
            comparison.t,
            comparison.camera[:, 2] * 1e3,
            color='tab:blue',
            lw=0.8,
            label='camera (/tip_pose)',
        )
        top.set_ylabel('tip z [mm]')
        top.set_title(
            f'camera vs reference: tracker clock = camera clock + {offset * 1e3:.4f} ms, '
            f'RMS difference {comparison.rms_difference_m * 1e6:.1f} um'
        )
        low, high = top.get_ylim()
        top.set_ylim(low, high + 0.25 * (high - low))  # room for the legend above the traces
        top.legend(loc='upper center', ncol=2)
        bottom.plot(comparison.t, comparison.difference[:, 2] * 1e6, color='tab:red', lw=0.6)
        bottom.axhline(0.0, color='k', lw=0.5)
        bottom.set_ylabel('camera - tracker z [um]')
        bottom.set_xlabel('time [s] (camera clock)')
        for axes in (top, bottom):
            axes.grid(alpha=0.3)
        figure.tight_layout()
        return save_figure(figure, path, dpi=110, what='the plot ')
    finally:
        plt.close(figure)
