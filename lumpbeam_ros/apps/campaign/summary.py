"""The campaign's summary: per-load statistics, the beam fit, the figure and the report."""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from lumpbeam_ros.apps.campaign.fit import BeamFit, fit_beam
from lumpbeam_ros.apps.campaign.task import Row
from lumpbeam_ros.core.model.parameters import BeamParameters

#: ``(column, label, scale, unit)`` of the quantities plotted against the load.
QUANTITIES = (
    ('natural_frequency_hz', 'natural frequency', 1.0, 'Hz'),
    ('damping_ratio', 'damping ratio', 1.0, ''),
    ('stiffness_total_nm_per_rad', 'k_tE (B.12)', 1.0, 'N m/rad'),
)

#: Loads closer than this are one group, kg.
LOAD_RESOLUTION_KG = 1e-6


@dataclass(frozen=True)
class LoadGroup:
    """The bags of one hanging load.

    Attributes:
        load_kg: m_l.
        n: Bags.
        means: Mean of each quantity over the bags.
        stds: Standard deviation of each quantity across the bags (NaN for one bag).
    """

    load_kg: float
    n: int
    means: dict[str, float]
    stds: dict[str, float]


#: The columns of a diagnosed bag's effect parameters (``lumpbeam diagnose``'s JSON, flat).
EFFECT_COLUMNS = 'effect_parameters.'


@dataclass(frozen=True)
class CampaignSummary:
    """What a campaign shows.

    Attributes:
        rows: Every row.
        ok: Rows with results.
        failed: ``(path, error)`` of the rows without.
        groups: One per load, increasing.
        beam_fit: EI and mass across the campaign (``None`` when it cannot be fitted).
        beam: The configured beam (L, g, m_d of the fit; its values for comparison).
        beam_fit_error: Why there is no fit.
    """

    rows: list[Row]
    ok: list[Row]
    failed: list[tuple[str, str]]
    groups: list[LoadGroup]
    beam_fit: BeamFit | None
    beam: BeamParameters
    beam_fit_error: str = ''

    @property
    def diagnoses(self) -> list[tuple[str, str, str]]:
        """``(bag, missing effect, its parameters)`` of every bag diagnosed, in row order."""
        found = []
        for row in self.ok:
            if not row.get('diagnosed') or row.get('missing_effect') is None:
                continue
            parameters = ', '.join(
                f'{key.removeprefix(EFFECT_COLUMNS)} = {value:.4g}'
                for key, value in row.items()
                if key.startswith(EFFECT_COLUMNS) and isinstance(value, int | float)
            )
            found.append((str(row['path']), str(row['missing_effect']), parameters))
        return found

    @property
    def configured(self) -> dict[str, float]:
        """The configured beam's EI (``k_tE L / 2``, B.6), k_tE and m_b, for comparison."""
        return {
            'bending_stiffness_nm2': self.beam.k_total_nm_per_rad * self.beam.length_m / 2.0,
            'k_total_nm_per_rad': self.beam.k_total_nm_per_rad,
            'beam_mass_kg': self.beam.mass_kg,
        }

    def text(self) -> str:
        """The printable summary: counts, the per-load table, the beam fit, the failures."""
        lines = [f'{len(self.rows)} rows: {len(self.ok)} with results, {len(self.failed)} failed']
        header = f'{"load kg":>8} {"bags":>5}'
        for _, label, _, unit in QUANTITIES:
            header += f' {label + (f" [{unit}]" if unit else ""):>30}'
        lines.append(header)
        for g in self.groups:
            line = f'{g.load_kg:>8.3g} {g.n:>5d}'
            for key, _, _, _ in QUANTITIES:
                line += f' {_mean_std(g.means[key], g.stds[key]):>30}'
            lines.append(line)
        fit = self.beam_fit
        if fit is None:
            lines.append(f'beam fit: none ({self.beam_fit_error})')
        else:
            c = self.configured
            measured = _mean_std(fit.frequency_measured_hz, fit.frequency_measured_hz_std)
            lines += [
                f'beam fit over {fit.n_bags} bags (B.3, B.1, B.5; chi2/n of the static line '
                f'{fit.static_chi2:.2f}):',
                f'  EI  = {_mean_std(fit.bending_stiffness_nm2, fit.bending_stiffness_nm2_std)}'
                f' N m^2   (configured k_tE L / 2 = {c["bending_stiffness_nm2"]:.6g})',
                f'  k_tE = {_mean_std(fit.k_total_nm_per_rad, fit.k_total_nm_per_rad_std)}'
                f' N m/rad (configured {c["k_total_nm_per_rad"]:.6g})',
                f'  m_b = {_mean_std(fit.beam_mass_kg, fit.beam_mass_kg_std)} kg '
                f'(configured {c["beam_mass_kg"]:.6g}), from the unloaded sag '
                f'{_mean_std(fit.unloaded_sag_m * 1e3, fit.unloaded_sag_m_std * 1e3)} mm',
                f'  frequency check: predicted {fit.frequency_predicted_hz:.5g} Hz from EI and '
                f'm_b, measured {measured} Hz',
            ]
        for path, effect, parameters in self.diagnoses:
            lines.append(
                f'diagnosis: {path}: {effect}' + (f' ({parameters})' if parameters else '')
            )
        for path, error in self.failed:
            lines.append(
                f'failed: {error}' if error.startswith(path) else f'failed: {path}: {error}'
            )
        return '\n'.join(lines)


def _mean_std(mean: float, std: float) -> str:
    if not math.isfinite(mean):
        return 'n/a'
    return f'{mean:.6g} +- {std:.2g}' if math.isfinite(std) else f'{mean:.6g}'


def _column(rows: list[Row], key: str) -> np.ndarray:
    return np.array([np.nan if r.get(key) is None else float(r[key]) for r in rows])


def summarize(rows: Iterable[Row], beam: BeamParameters) -> CampaignSummary:
    """Groups the rows by load and fits the beam across them.

    Args:
        rows: The campaign's rows.
        beam: The configured beam (L, g, m_d for the fit; its values for comparison).

    Returns:
        The summary.
    """
    rows = list(rows)
    ok = [r for r in rows if not r.get('error')]
    failed = [(r['path'], r['error']) for r in rows if r.get('error')]
    groups: list[LoadGroup] = []
    loads = _column(ok, 'load_kg')
    finite = np.isfinite(loads)
    for load in np.unique(np.round(loads[finite] / LOAD_RESOLUTION_KG) * LOAD_RESOLUTION_KG):
        members = [r for r, x in zip(ok, loads, strict=True) if abs(x - load) < LOAD_RESOLUTION_KG]
        means, stds = {}, {}
        for key, *_ in QUANTITIES:
            values = _column(members, key)
            values = values[np.isfinite(values)]
            means[key] = float(np.mean(values)) if values.size else math.nan
            stds[key] = float(np.std(values, ddof=1)) if values.size > 1 else math.nan
        groups.append(LoadGroup(float(load), len(members), means, stds))
    columns = (
        'load_kg',
        'static_deflection_m',
        'static_deflection_m_std',
        'level_after_m',
        'level_after_m_std',
        'natural_frequency_hz',
        'natural_frequency_hz_std',
    )
    data = np.array([_column(ok, c) for c in columns]) if ok else np.zeros((len(columns), 0))
    usable = np.all(np.isfinite(data), axis=0) & (data[2] > 0) & (data[4] > 0) & (data[6] > 0)
    try:
        load, deflection, deflection_std, level, level_std, frequency, frequency_std = data[
            :, usable
        ]
        beam_fit = fit_beam(
            load, deflection, deflection_std, level, level_std, frequency, frequency_std,
            beam.length_m, beam.gravity_mps2, beam.tip_mass_kg,
        )  # fmt: skip
        error = ''
    except ValueError as exc:
        beam_fit, error = None, str(exc)
    return CampaignSummary(rows, ok, failed, groups, beam_fit, beam, error)


def summary_figure(summary: CampaignSummary) -> bytes:
    """The summary figure: each quantity against the load, and the static line (B.3).

    Frequency, damping and k_tE per bag with its 1 sigma and per load with the spread across
    bags; delta_vE against the load with the line of the fitted EI.

    Returns:
        PNG bytes.
    """
    import matplotlib

    matplotlib.use('Agg')
    import matplotlib.pyplot as plt

    from lumpbeam_ros.apps.report.html import figure_png

    fig, axes = plt.subplots(2, 2, figsize=(11, 8))
    loads = _column(summary.ok, 'load_kg')
    for ax, (key, label, scale, unit) in zip(axes.flat, QUANTITIES, strict=False):
        values, stds = _column(summary.ok, key), _column(summary.ok, f'{key}_std')
        ax.errorbar(
            loads,
            scale * values,
            yerr=scale * stds,
            fmt='.',
            color='0.55',
            ms=4,
            capsize=2,
            label='bags (1 sigma of each fit)',
        )
        g_load = [g.load_kg for g in summary.groups]
        ax.errorbar(
            g_load,
            [scale * g.means[key] for g in summary.groups],
            yerr=[scale * g.stds[key] for g in summary.groups],
            fmt='o',
            color='tab:blue',
            capsize=4,
            label='mean, std across bags',
        )
        ax.set_xlabel('hanging load m_l, kg')
        ax.set_ylabel(f'{label}' + (f', {unit}' if unit else ''))
        ax.grid(alpha=0.3)
    axes[0, 0].legend(fontsize=8)
    fit = summary.beam_fit
    if fit is not None:
        for ax, value, label in (
            (axes[0, 0], fit.frequency_predicted_hz, 'from the static fit (Rayleigh)'),
            (axes[1, 0], fit.k_total_nm_per_rad, '2 EI / L across the campaign'),
        ):
            ax.axhline(value, color='tab:red', ls='--', lw=1, label=label)
            ax.legend(fontsize=8)
    ax = axes[1, 1]
    deflection = _column(summary.ok, 'static_deflection_m')
    ax.errorbar(
        loads,
        1e3 * deflection,
        yerr=1e3 * _column(summary.ok, 'static_deflection_m_std'),
        fmt='.',
        color='0.4',
        capsize=2,
        label='bags',
    )
    if fit is not None and np.any(np.isfinite(loads)):
        line = np.linspace(0.0, float(np.nanmax(loads)), 50)
        beam = summary.beam
        per_newton = beam.length_m**3 / (3.0 * fit.bending_stiffness_nm2)  # B.3
        ax.plot(
            line,
            1e3 * line * beam.gravity_mps2 * per_newton,
            color='tab:red',
            lw=1,
            label=f'B.3, EI = {fit.bending_stiffness_nm2:.5g} N m^2',
        )
    ax.set_xlabel('hanging load m_l, kg')
    ax.set_ylabel('static deflection delta_vE, mm')
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.suptitle(f'Campaign: {len(summary.ok)} bags with results, {len(summary.failed)} failed')
    return figure_png(fig)


def write_campaign_report(summary: CampaignSummary, path: str | Path) -> Path:
    """Writes ``RESULTS/report.html``: the per-load table, the beam fit, the figure, failures.

    Args:
        summary: The campaign's summary.
        path: The ``.html`` file.

    Returns:
        The file written.

    Raises:
        LumpbeamError: It cannot be written.
    """
    from lumpbeam_ros.apps.campaign import fit as fit_module
    from lumpbeam_ros.apps.report.html import HtmlReport

    page = HtmlReport('lumpbeam campaign')
    page.paragraph(
        f'{len(summary.rows)} bags: {len(summary.ok)} with results, {len(summary.failed)} failed.'
    )
    page.heading('Against the hanging load (mean and standard deviation across bags)')
    header = ['load, kg', 'bags']
    for _, label, _, unit in QUANTITIES:
        header += [f'{label}' + (f', {unit}' if unit else ''), 'std']
    page.table(
        header,
        [
            [g.load_kg, g.n, *(v for key, *_ in QUANTITIES for v in (g.means[key], g.stds[key]))]
            for g in summary.groups
        ],
    )
    page.heading("The beam across the campaign (the paper's Table B.1 method, from data)")
    page.paragraph(fit_module.METHOD)
    fit = summary.beam_fit
    if fit is None:
        page.paragraph(f'No fit: {summary.beam_fit_error}', note=True)
    else:
        c = summary.configured
        page.table(
            ['quantity', 'fitted', 'std', 'configured'],
            [
                [
                    'EI, N m^2',
                    fit.bending_stiffness_nm2,
                    fit.bending_stiffness_nm2_std,
                    c['bending_stiffness_nm2'],
                ],
                [
                    'k_tE = 2 EI / L, N m/rad',
                    fit.k_total_nm_per_rad,
                    fit.k_total_nm_per_rad_std,
                    c['k_total_nm_per_rad'],
                ],
                ['m_b, kg', fit.beam_mass_kg, fit.beam_mass_kg_std, c['beam_mass_kg']],
                ['unloaded sag delta_0, m', fit.unloaded_sag_m, fit.unloaded_sag_m_std, None],
                ['chi2/n of the static line', fit.static_chi2, None, None],
                ['f unloaded, predicted from EI, m_b, Hz', fit.frequency_predicted_hz, None, None],
                [
                    'f unloaded, measured (weighted mean), Hz',
                    fit.frequency_measured_hz,
                    fit.frequency_measured_hz_std,
                    None,
                ],
            ],
        )
    page.png(summary_figure(summary), 'frequency, damping and stiffness against the load')
    if summary.diagnoses:
        page.heading('The diagnosis of each bag (lumpbeam diagnose)')
        page.table(['bag', 'missing effect', 'its parameters'], summary.diagnoses)
    if summary.failed:
        page.heading('Bags without results')
        page.table(['bag', 'error'], [list(item) for item in summary.failed])
    return page.write(path)


def fit_dict(summary: CampaignSummary) -> dict[str, float]:
    """The beam fit as a dictionary (empty when there is none)."""
    return asdict(summary.beam_fit) if summary.beam_fit is not None else {}
