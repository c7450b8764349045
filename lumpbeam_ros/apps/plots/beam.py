"""The beam drawn from its markers: snapshots of ``/beam_markers`` as a viewer would show them.

:func:`plot_beam_snapshots` reads what a bag's ``/beam_markers`` hold (the line strip through
the chain's joints, the measured and predicted tips, the hanging load) and draws a few
instants on top of each other, with the tips' height over the whole record below, so the
figure shows exactly what Foxglove or RViz draw from the same bag. The sag of a stiff beam is
a few centimetres over metres, so the vertical axis is in millimetres (exaggerated).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from lumpbeam_ros.apps.plots.files import save_figure
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.viz.marker_messages import read_marker_arrays
from lumpbeam_ros.core.viz.markers import (
    NS_BEAM,
    NS_LOAD,
    NS_MEASURED,
    NS_PREDICTED,
    Action,
    MarkerSpec,
)

#: Snapshots drawn when no times are given.
DEFAULT_SNAPSHOTS = 6


def _find(markers: Sequence[MarkerSpec], namespace: str) -> MarkerSpec | None:
    return next((m for m in markers if m.namespace == namespace and m.action == Action.ADD), None)


def _tip_series(
    arrays: Sequence[tuple[float, list[MarkerSpec]]], namespace: str
) -> tuple[np.ndarray, np.ndarray]:
    rows = [(t, m.position[2]) for t, markers in arrays if (m := _find(markers, namespace))]
    data = np.array(rows, dtype=float).reshape(-1, 2)
    return data[:, 0], data[:, 1]


def snapshot_indices(stamps: np.ndarray, times: Sequence[float] | None, count: int) -> list[int]:
    """The arrays nearest to ``times`` (default: ``count`` spread evenly over the record).

    Args:
        stamps: The arrays' stamps, s, increasing.
        times: Wanted instants, s; ``None`` spreads ``count`` of them.
        count: How many when spreading.

    Returns:
        Distinct indices into ``stamps``, in time order.
    """
    wanted = np.linspace(stamps[0], stamps[-1], count) if times is None else times
    return sorted({int(np.argmin(np.abs(stamps - t))) for t in wanted})


def finish_snapshot_axis(
    axis: Any, times: np.ndarray, colors: Any, event: tuple[float | None, str]
) -> None:
    """The time axis under a snapshot figure: a line at each snapshot and at the event.

    Each snapshot is dotted in its colour; the event (the release, the end of a move) is
    dashed, when its time is known.

    Args:
        axis: The matplotlib axes.
        times: The snapshots' stamps, s.
        colors: Their colours, in order.
        event: ``(time_s or None, label)``.
    """
    for color, t in zip(colors, times, strict=True):
        axis.axvline(t, color=color, lw=0.8, ls=':')
    event_s, label = event
    if event_s is not None:
        axis.axvline(event_s, color='gray', lw=1.0, ls='--', label=label)
    axis.set_xlabel('time (s, header stamp)')
    axis.grid(alpha=0.3)


def plot_beam_snapshots(
    bag: str | Path,
    path: str | Path,
    *,
    times: Sequence[float] | None = None,
    release_time_s: float | None = None,
    title: str = 'The beam as /beam_markers draw it',
) -> Path:
    """Draws a bag's ``/beam_markers`` at a few instants and the tips over time.

    Args:
        bag: A bag with ``/beam_markers``.
        path: Output image (PNG); its folder is created.
        times: Instants to draw (header stamps, s); the nearest array of each is drawn.
            ``None``: six spread over the record.
        release_time_s: Marks the load's release in the lower plot, if given.
        title: Figure title.

    Returns:
        The written path.

    Raises:
        BagError: The bag cannot be read or has no ``/beam_markers``.
        LumpbeamError: No array draws a beam, or the file cannot be written.
    """
    import matplotlib

    matplotlib.use('Agg')
    from matplotlib import pyplot as plt

    arrays = [(t, m) for t, m in read_marker_arrays(bag) if _find(m, NS_BEAM) is not None]
    if not arrays:
        raise LumpbeamError(f'{bag}: no /beam_markers message draws the beam')
    stamps = np.array([t for t, _ in arrays])
    chosen = snapshot_indices(stamps, times, DEFAULT_SNAPSHOTS)
    figure, (shape_axis, time_axis) = plt.subplots(
        2, 1, figsize=(9, 7), gridspec_kw={'height_ratios': [3, 2]}
    )
    try:
        colors = plt.get_cmap('viridis')(np.linspace(0.0, 0.9, len(chosen)))
        for color, index in zip(colors, chosen, strict=True):
            t, markers = arrays[index]
            beam = _find(markers, NS_BEAM)
            assert beam is not None  # arrays were filtered on it
            shape_axis.plot(
                beam.points[:, 0], beam.points[:, 2] * 1e3, '-o', ms=2.5, lw=1.2, color=color,
                label=f't = {t:.2f} s',
            )  # fmt: skip
            for namespace, style in ((NS_MEASURED, 'x'), (NS_PREDICTED, '+')):
                tip = _find(markers, namespace)
                if tip is not None:
                    shape_axis.plot(
                        tip.position[0], tip.position[2] * 1e3, style, ms=9, color=color
                    )
            load = _find(markers, NS_LOAD)
            if load is not None:
                shape_axis.plot(
                    load.position[0], load.position[2] * 1e3, 's', ms=8, color=color, alpha=0.6
                )
        shape_axis.set_xlabel('x in beam_base (m)')
        shape_axis.set_ylabel('z (mm, exaggerated)')
        shape_axis.grid(alpha=0.3)
        shape_axis.legend(fontsize=8, ncol=2, loc='lower left')
        shape_axis.set_title('line strip through the joints; x measured tip, + predicted tip, '
                             'square: the hanging load', fontsize=9)  # fmt: skip
        for namespace, label in ((NS_MEASURED, 'measured tip'), (NS_PREDICTED, 'predicted tip')):
            tip_t, tip_z = _tip_series(arrays, namespace)
            if tip_t.size:
                time_axis.plot(tip_t, tip_z * 1e3, lw=0.8, label=label)
        finish_snapshot_axis(time_axis, stamps[chosen], colors, (release_time_s, 'release'))
        time_axis.set_ylabel('tip z (mm)')
        time_axis.legend(fontsize=8, loc='lower right')
        figure.suptitle(title)
        figure.tight_layout()
        return save_figure(figure, path, dpi=110)
    finally:
        plt.close(figure)


def drop_snapshot_times(release_time_s: float, period_s: float) -> list[float]:
    """Instants that show a drop: at rest before it, then every quarter of the first period.

    Args:
        release_time_s: When the load left, s.
        period_s: The unloaded beam's first period, s.

    Returns:
        Six instants, s.
    """
    return [release_time_s - 0.5] + [release_time_s + k * period_s / 4.0 for k in range(5)]
