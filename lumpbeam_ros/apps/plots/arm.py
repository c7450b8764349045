"""The arm drawn from its markers: snapshots of ``/beam_markers`` during and after a move.

:func:`plot_arm_snapshots` reads the link strips a bag's ``/beam_markers`` hold (namespace
``arm_link``: one line strip per link through its segments' ends; the joints in
``arm_joints``) and draws a few instants in the x-z plane of ``beam_base`` at true scale, with
the tip's height over the whole record below (its ring-down after the move magnified), so the
figure shows what Foxglove or RViz draw from the same bag.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from lumpbeam_ros.apps.plots.beam import DEFAULT_SNAPSHOTS, finish_snapshot_axis, snapshot_indices
from lumpbeam_ros.apps.plots.files import save_figure
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.viz.marker_messages import read_marker_arrays
from lumpbeam_ros.core.viz.markers import NS_JOINTS, NS_LINK, NS_MEASURED, Action, MarkerSpec


def _links(markers: Sequence[MarkerSpec]) -> list[MarkerSpec]:
    found = [m for m in markers if m.namespace == NS_LINK and m.action == Action.ADD]
    return sorted(found, key=lambda m: m.marker_id)


def plot_arm_snapshots(
    bag: str | Path,
    path: str | Path,
    *,
    times: Sequence[float] | None = None,
    move_end_s: float | None = None,
    title: str = 'The arm as /beam_markers draw it',
) -> Path:
    """Draws a bag's arm at a few instants (x-z plane, true scale) and its tip over time.

    Args:
        bag: A bag whose ``/beam_markers`` draw an arm (``lumpbeam synth --arm``).
        path: Output image (PNG); its folder is created.
        times: Instants to draw (header stamps, s); the nearest array of each is drawn.
            ``None``: six spread over the record.
        move_end_s: Marks the end of the move in the lower plot, if given.
        title: Figure title.

    Returns:
        The written path.

    Raises:
        BagError: The bag cannot be read or has no ``/beam_markers``.
        LumpbeamError: No array draws an arm, or the file cannot be written.
    """
    import matplotlib

    matplotlib.use('Agg')
    from matplotlib import pyplot as plt

    arrays = [(t, m) for t, m in read_marker_arrays(bag) if _links(m)]
    if not arrays:
        raise LumpbeamError(f'{bag}: no /beam_markers message draws an arm')
    stamps = np.array([t for t, _ in arrays])
    chosen = snapshot_indices(stamps, times, DEFAULT_SNAPSHOTS)
    figure, (shape_axis, time_axis) = plt.subplots(
        2, 1, figsize=(7, 7), gridspec_kw={'height_ratios': [3, 1.4]}
    )
    try:
        colors = plt.get_cmap('viridis')(np.linspace(0.0, 0.9, len(chosen)))
        for color, index in zip(colors, chosen, strict=True):
            t, markers = arrays[index]
            for i, link in enumerate(_links(markers)):
                shape_axis.plot(
                    link.points[:, 0], link.points[:, 2], '-', lw=2.0 if i % 2 else 3.0,
                    color=color, label=f't = {t:.2f} s' if i == 0 else None,
                )  # fmt: skip
            joints = next((m for m in markers if m.namespace == NS_JOINTS), None)
            if joints is not None:
                shape_axis.plot(joints.points[:, 0], joints.points[:, 2], 'o', ms=5, color=color)
        shape_axis.plot(0.0, 0.0, 'ks', ms=8)
        shape_axis.set_aspect('equal', adjustable='datalim')
        shape_axis.set_xlabel('x in beam_base (m)')
        shape_axis.set_ylabel('z (m)')
        shape_axis.grid(alpha=0.3)
        shape_axis.legend(fontsize=8, loc='best')
        shape_axis.set_title('a line strip per link through its segments; dots: the joints',
                             fontsize=9)  # fmt: skip
        tips = [(t, m.position[2]) for t, ms in arrays for m in ms if m.namespace == NS_MEASURED]
        tip = np.array(tips, dtype=float).reshape(-1, 2)
        time_axis.plot(tip[:, 0], tip[:, 1], lw=0.8, color='tab:red', label='measured tip z')
        finish_snapshot_axis(time_axis, stamps[chosen], colors, (move_end_s, 'end of the move'))
        time_axis.set_ylabel('tip z (m)')
        time_axis.legend(fontsize=8, loc='best')
        figure.suptitle(title)
        figure.tight_layout()
        return save_figure(figure, path, dpi=80)
    finally:
        plt.close(figure)
