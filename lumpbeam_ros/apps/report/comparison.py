"""The HTML report of ``lumpbeam compare --report``: alignment, differences, both estimates."""

from __future__ import annotations

import tempfile
from pathlib import Path

import matplotlib

matplotlib.use('Agg')  # files only: no display

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from lumpbeam_ros.apps.plots.comparison import plot_comparison  # noqa: E402
from lumpbeam_ros.apps.report.html import HtmlReport, as_cell, figure_png  # noqa: E402
from lumpbeam_ros.core.compare.comparison import Comparison  # noqa: E402
from lumpbeam_ros.core.ident.bag_analysis import CONTRACT_KEYS  # noqa: E402

AXES = ('x', 'y', 'z')


def difference_figure(comparison: Comparison) -> bytes:
    """The camera-minus-reference residual on each axis over time, as PNG."""
    fig, axes = plt.subplots(3, 1, figsize=(9, 6), sharex=True)
    difference = 1e6 * comparison.difference
    for i, ax in enumerate(axes):
        rms = float(np.sqrt(np.mean(difference[:, i] ** 2)))
        ax.plot(comparison.t, difference[:, i], lw=0.5)
        ax.axhline(0.0, color='0.4', lw=0.6)
        ax.set_ylabel(f'{AXES[i]}, um')
        ax.set_title(f'camera - tracker along {AXES[i]}: RMS {rms:.1f} um', fontsize=9)
    axes[-1].set_xlabel('camera time, s')
    return figure_png(fig)


def write_comparison_report(comparison: Comparison, bag: str | Path, path: str | Path) -> Path:
    """Writes the report of ``lumpbeam compare --report``.

    Args:
        comparison: The result of :func:`~lumpbeam_ros.core.compare.comparison.compare_sensors`.
        bag: The bag it came from.
        path: The ``.html`` file.

    Returns:
        The file written.

    Raises:
        LumpbeamError: Not an ``.html`` path, or it cannot be written.
    """
    data = comparison.as_dict()
    page = HtmlReport(f'lumpbeam compare: {Path(bag).name}')
    page.paragraph(f'{bag}: {data["pairs"]} pairs, {data["reference_samples"]} reference samples')
    page.heading('Alignment (1 sigma)')
    transform = data['transform']
    rows = [
        [
            'time offset, s (tracker = camera + offset)',
            data['time_offset_s'],
            data['time_offset_s_std'],
        ],
        ['coarse offset, s (cross-correlation)', data['coarse_time_offset_s'], None],
    ]
    for i, axis in enumerate(AXES):
        rows.append(
            [
                f'translation {axis}, m',
                transform['translation_m'][i],
                transform['translation_std_m'][i],
            ]
        )
    for i, axis in enumerate(AXES):
        rows.append([f'rotation about {axis}, rad (std)', None, transform['rotation_std_rad'][i]])
    rows.append(['off-plane RMS, m', transform['plane_rms_m'], None])
    page.table(['figure', 'value', 'std'], rows)
    page.heading('Difference after alignment (camera - tracker)')
    page.table(
        ['figure', 'value, m'],
        [['RMS (z)', data['rms_difference_m']], ['max (z)', data['max_difference_m']]]
        + [[f'RMS ({a})', v] for a, v in data['rms_difference_by_axis_m'].items()],
    )
    page.png(difference_figure(comparison), 'residual camera - tracker')
    page.heading('Identification from each sensor (1 sigma)')
    sensors = data['per_sensor']
    page.table(
        ['estimate', 'camera', 'camera std', 'tracker', 'tracker std'],
        [
            [
                key,
                *(
                    as_cell(sensors[s].get(k))
                    for s in ('camera', 'tracker')
                    for k in (key, f'{key}_std')
                ),
            ]
            for key in CONTRACT_KEYS
        ],
    )
    with tempfile.TemporaryDirectory(prefix='lumpbeam-report-') as tmp:
        page.png_files([plot_comparison(comparison, tmp)])
    return page.write(path)
