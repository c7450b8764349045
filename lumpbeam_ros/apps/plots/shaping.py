"""The live loop's figure: how the tip rings after an unshaped move and after a shaped one."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use('Agg')  # before pyplot: files only, no display

import matplotlib.pyplot as plt  # noqa: E402

from lumpbeam_ros.apps.plots.files import save_figure  # noqa: E402
from lumpbeam_ros.core.shaping.loop import ShapingOutcome  # noqa: E402


def plot_shaping_outcome(outcome: ShapingOutcome, path: str | Path) -> Path:
    """The tip's distance from its rest after each move, both residuals in the legend.

    Args:
        outcome: The unshaped and the shaped move.
        path: PNG file to write.

    Returns:
        The path written.

    Raises:
        LumpbeamError: The file cannot be written.
    """
    fig, ax = plt.subplots(figsize=(9, 4.5))
    for residual, label, color in (
        (outcome.unshaped, 'unshaped', 'tab:red'),
        (outcome.shaped, 'shaped', 'tab:blue'),
    ):
        ax.plot(
            residual.t,
            1e3 * residual.distance_m,
            lw=0.8,
            color=color,
            label=f'{label}: residual {1e3 * residual.residual_m:.3g} mm RMS',
        )
    top = max(float(outcome.unshaped.distance_m.max(initial=0.0)), 1e-9) * 1e3
    ax.set_ylim(0.0, 1.3 * top)  # room for the legend above the curves
    ax.set_xlabel('time after the move ends (s)')
    ax.set_ylabel("tip's distance from its rest (mm)")
    ax.set_title(f'residual vibration {100 * outcome.reduction:.1f} % less with input shaping')
    ax.grid(alpha=0.3)
    ax.legend(loc='upper right')
    fig.tight_layout()
    try:
        return save_figure(fig, path, dpi=110, what='the plot ')
    finally:
        plt.close(fig)
