"""The live loops' figures: how the tip rings after unshaped and shaped moves."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Protocol

import matplotlib
import numpy as np

matplotlib.use('Agg')  # before pyplot: files only, no display

import matplotlib.pyplot as plt  # noqa: E402

from lumpbeam_ros.apps.plots.files import save_figure  # noqa: E402
from lumpbeam_ros.core.shaping.loop import MoveResidual, ShapingOutcome  # noqa: E402


class WorkspaceMove(Protocol):
    """One move of the workspace demo, as its figure draws it."""

    @property
    def number(self) -> int: ...  # noqa: D102
    @property
    def shaped_by(self) -> str: ...  # noqa: D102
    @property
    def measured(self) -> MoveResidual: ...  # noqa: D102
    @property
    def unshaped_m(self) -> float: ...  # noqa: D102
    @property
    def file_model_m(self) -> float: ...  # noqa: D102
    @property
    def reduction(self) -> float: ...  # noqa: D102


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


def plot_workspace_outcome(outcomes: Sequence[WorkspaceMove], path: str | Path) -> Path:
    """Each move's residual on the arm beside its references, and the tip after each move.

    Left: per move, the residual unshaped (simulated), shaped by the arm file's model
    (simulated) and as measured, on a log scale. Right: the tip's measured distance from its
    rest after each move.

    Args:
        outcomes: The moves of ``lumpbeam demo --workspace``.
        path: PNG file to write.

    Returns:
        The path written.

    Raises:
        LumpbeamError: The file cannot be written.
    """
    fig, (bars, curves) = plt.subplots(1, 2, figsize=(12, 4.8))
    numbers = np.array([o.number for o in outcomes], dtype=float)
    width = 0.27
    for offset, values, label, color in (
        (-width, [o.unshaped_m for o in outcomes], 'unshaped (simulated)', 'tab:red'),
        (
            0.0,
            [o.file_model_m for o in outcomes],
            "shaped by the file's model (simulated)",
            'tab:orange',
        ),
        (width, [o.measured.residual_m for o in outcomes], 'as run (measured)', 'tab:blue'),
    ):
        bars.bar(numbers + offset, 1e3 * np.asarray(values), width, label=label, color=color)
    bars.set_yscale('log')
    ticks = [f'{o.number}\n' + o.shaped_by.replace(' (', '\n(') for o in outcomes]
    bars.set_xticks(numbers, ticks, fontsize=7)
    bars.set_ylabel('residual vibration (mm RMS over 3 s)')
    bars.set_title('each move, learned as it goes')
    bars.grid(alpha=0.3, axis='y')
    bars.legend(fontsize=8)
    for outcome in outcomes:
        residual = outcome.measured
        label = f'move {outcome.number}: ' + (
            f'{100 * outcome.reduction:.2f} % less'
            if outcome.shaped_by != 'unshaped'
            else 'unshaped'
        )
        # A floor of 1 nm: a log scale has no zero.
        distance = np.maximum(1e3 * residual.distance_m, 1e-6)
        curves.plot(residual.t, distance, lw=0.8, label=label)
    curves.set_yscale('log')
    curves.set_xlabel('time after the move ends (s)')
    curves.set_ylabel("tip's distance from its rest (mm)")
    curves.set_title('measured after each move')
    curves.grid(alpha=0.3)
    curves.legend(fontsize=8, loc='lower right')
    fig.tight_layout()
    try:
        return save_figure(fig, path, dpi=110, what='the plot ')
    finally:
        plt.close(fig)
