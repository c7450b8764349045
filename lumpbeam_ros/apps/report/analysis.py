"""The HTML report of ``lumpbeam analyze --report``: estimates, fit over the data, residuals."""

from __future__ import annotations

import tempfile
from pathlib import Path

import matplotlib

matplotlib.use('Agg')  # files only: no display

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from lumpbeam_ros.apps.plots.analysis import write_analysis_plots  # noqa: E402
from lumpbeam_ros.apps.report.html import HtmlReport, as_cell, estimate_rows, figure_png  # noqa: E402
from lumpbeam_ros.core.ident.bag_analysis import CONTRACT_KEYS, BagAnalysis, result_json  # noqa: E402

#: Further estimates shown with their uncertainty, after the headline ones.
CROSS_CHECKS = (
    'release_time_s',
    'static_deflection_m',
    'level_before_m',
    'level_after_m',
    'log_decrement',
    'log_decrement_b20',
    'damping_ratio_b20',
    'damped_frequency_b20_hz',
    'stiffness_vertical_from_frequency_n_per_m',
    'stiffness_total_from_pitch_nm_per_rad',
)

#: Figures of the fit itself, without an uncertainty.
FIT_FACTS = (
    'status',
    'message',
    'method',
    'release_source',
    'released_load_kg',
    'cycles',
    'amplitude_m',
    'residual_rms_m',
    'covariance_inflation',
    'natural_frequency_pencil_hz',
    'damping_ratio_pencil',
    'second_mode_hz',
    'n_samples',
    'n_rejected',
)


def fit_residual_figure(analysis: BagAnalysis) -> bytes | None:
    """The fitted decay over the measured tip z, and the residual (measured - fit), as PNG.

    Args:
        analysis: The bag's analysis.

    Returns:
        The PNG bytes, or ``None`` when nothing was fitted.
    """
    if analysis.fit is None:
        return None
    params = analysis.fit.params
    w = analysis.window
    fitted = w.t >= params.t0
    t, z = w.t[fitted], w.z[fitted]
    model = params.predict(t)
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    top.plot(w.t, 1e3 * w.z, '.', ms=1.5, color='0.5', label='measured tip z')
    top.plot(t, 1e3 * model, lw=1.0, color='tab:blue', label=f'fit ({analysis.result.method})')
    top.set_ylabel('tip z, mm')
    top.legend(loc='lower right', fontsize=8)
    top.set_title('The fitted decay over the data')
    residual = 1e6 * (z - model)
    rms = float(np.sqrt(np.mean(residual**2)))
    bottom.plot(t, residual, lw=0.6, color='tab:red')
    bottom.axhline(0.0, color='0.4', lw=0.6)
    bottom.set_ylabel('measured - fit, um')
    bottom.set_xlabel('time, s')
    bottom.set_title(f'Residual: RMS {rms:.1f} um over {t.size} samples', fontsize=9)
    return figure_png(fig)


def add_analysis(page: HtmlReport, analysis: BagAnalysis) -> None:
    """Adds an analysis's estimates, fit and figures to a page.

    Args:
        page: The report being built.
        analysis: The bag's analysis.
    """
    data = result_json(analysis.result)
    w = analysis.window
    page.paragraph(
        f'{analysis.bag}: {len(w)} poses over {w.end_s - w.start_s:.2f} s; '
        f'status {data["status"]}' + (f' ({data["message"]})' if data['message'] else '')
    )
    page.heading('Estimates (1 sigma)')
    page.table(['estimate', 'value', 'std'], estimate_rows(data, CONTRACT_KEYS + CROSS_CHECKS))
    page.heading('The fit')
    page.table(['figure', 'value'], [[key, as_cell(data.get(key))] for key in FIT_FACTS])
    png = fit_residual_figure(analysis)
    if png is None:
        page.paragraph('No decay was fitted, so there is no fit or residual to show.', True)
    else:
        page.png(png, 'fit and residual')
    with tempfile.TemporaryDirectory(prefix='lumpbeam-report-') as tmp:
        page.png_files(write_analysis_plots(w, analysis.result, Path(tmp)))


def write_analysis_report(analysis: BagAnalysis, path: str | Path) -> Path:
    """Writes the report of ``lumpbeam analyze --report``.

    Args:
        analysis: The bag's analysis.
        path: The ``.html`` file.

    Returns:
        The file written.

    Raises:
        LumpbeamError: Not an ``.html`` path, or it cannot be written.
    """
    page = HtmlReport(f'lumpbeam analyze: {analysis.bag.name}')
    add_analysis(page, analysis)
    return page.write(path)
