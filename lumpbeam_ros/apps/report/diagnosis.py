"""The HTML report of ``lumpbeam diagnose --report``: the verdict and the gap before and after."""

from __future__ import annotations

import tempfile
from pathlib import Path

from lumpbeam_ros.apps.report.html import Cell, HtmlReport
from lumpbeam_ros.core.diagnose.workflow import Diagnosis

GAP_COLUMNS = ('rms_m', 'max_m', 'frequency_error', 'damping_error')


def add_diagnosis(page: HtmlReport, diagnosis: Diagnosis) -> None:
    """Adds a diagnosis: the verdict, the gaps, the candidates and the figures.

    Args:
        page: The report being built.
        diagnosis: The result of :func:`~lumpbeam_ros.core.diagnose.workflow.diagnose`.
    """
    from lumpbeam_ros.apps.plots.diagnosis import plot_diagnosis  # matplotlib only here

    d = diagnosis
    page.heading(f'Missing effect: {d.missing_effect}')
    page.paragraph(d.decision.reason)
    if d.effect_parameters:
        page.table(
            ['effect parameter', 'value'],
            [[name, value] for name, value in d.effect_parameters.items()],
        )
    page.paragraph(
        f'Measurement noise: z {d.noise_z_m * 1e6:.2f} um, pitch '
        f'{d.noise_pitch_rad * 1e6:.2f} urad; candidates fitted up to {d.train_end_s:.3f} s '
        f'and checked on the rest; {d.simulations} simulations.',
        note=True,
    )
    page.heading('The gap between model and measurement')
    rows: list[list[Cell]] = []
    for label, gap in (
        ('configured beam (as given)', d.gap_configured),
        ('before: nominal, refit', d.gap_before),
        (f'after: with {d.missing_effect}', d.gap_after),
    ):
        values = gap.as_dict()
        rows.append([label, *(values[c] for c in GAP_COLUMNS)])
    page.table(['model', *GAP_COLUMNS], rows)
    page.heading('Candidates (BIC on the fitted part, lower is better)')
    page.table(
        ['candidate', 'BIC', 'held-out chi2/n', 'record chi2/n', 'physical', 'parameters'],
        [
            [
                s.name,
                s.bic,
                s.holdout_chi2,
                s.record_chi2,
                str(s.physical),
                ', '.join(f'{k} = {v:.5g}' for k, v in s.parameters.items()),
            ]
            for s in [d.nominal, *d.candidates]
        ],
    )
    with tempfile.TemporaryDirectory(prefix='lumpbeam-report-') as tmp:
        page.png_files(plot_diagnosis(d, tmp))


def write_diagnosis_report(diagnosis: Diagnosis, bag: str | Path, path: str | Path) -> Path:
    """Writes the report of ``lumpbeam diagnose --report``.

    Args:
        diagnosis: The diagnosis.
        bag: The bag it came from (named in the title).
        path: The ``.html`` file.

    Returns:
        The file written.

    Raises:
        LumpbeamError: Not an ``.html`` path, or it cannot be written.
    """
    page = HtmlReport(f'lumpbeam diagnose: {Path(bag).name}')
    page.paragraph(f'{bag}: {len(diagnosis.record)} poses')
    add_diagnosis(page, diagnosis)
    return page.write(path)
