"""Figures of a diagnosis: fits, residuals before and after, signatures, candidates' scores.

The signatures are what singled out each effect: the time shift at the load event, the
frequency against the amplitude, the envelope law of the peaks.
"""

from __future__ import annotations

import textwrap
from pathlib import Path

import matplotlib

matplotlib.use('Agg')  # files only: no display on a robot or a CI runner

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from lumpbeam_ros.apps.plots.lines import broken_at_gaps  # noqa: E402
from lumpbeam_ros.base.errors import LumpbeamError  # noqa: E402
from lumpbeam_ros.core.diagnose.gap import SETTLE_S  # noqa: E402
from lumpbeam_ros.core.diagnose.live import named_effects  # noqa: E402
from lumpbeam_ros.core.diagnose.signatures import decay_peaks  # noqa: E402
from lumpbeam_ros.core.diagnose.workflow import Diagnosis  # noqa: E402
from lumpbeam_ros.core.model.parameters import EFFECTS  # noqa: E402
from lumpbeam_ros.core.model.trajectory import TipTrajectory  # noqa: E402

#: The candidates figure's title is wrapped at this many characters (its reason is long).
TITLE_CHARS = 160

#: The files :func:`plot_diagnosis` writes.
FIGURES = (
    'diagnosis_fit.png',
    'diagnosis_residuals.png',
    'diagnosis_signatures.png',
    'diagnosis_candidates.png',
)

#: Which effects each signature panel speaks for.
SIGNATURE_EFFECTS = {
    panel: tuple(name for name, record in EFFECTS.items() if record.signature == panel)
    for panel in ('time_shift', 'frequency', 'envelope')
}


def _fit_figure(d: Diagnosis, path: Path) -> None:
    fig, axes = plt.subplots(2, 1, figsize=(10, 6), sharex=True)
    r = d.record
    label_after = f'augmented ({d.missing_effect})'
    for ax, name, scale, unit in ((axes[0], 'z', 1e3, 'mm'), (axes[1], 'pitch', 1e3, 'mrad')):
        ax.plot(r.t, getattr(r, name) * scale, '.', ms=1.5, color='0.5', label='measured')
        ax.plot(
            *broken_at_gaps(d.before.t, getattr(d.before, name) * scale),
            lw=1.0,
            label='nominal (refit)',
        )
        ax.plot(*broken_at_gaps(d.after.t, getattr(d.after, name) * scale), lw=1.0, ls='--',
                label=label_after)  # fmt: skip
        ax.axvline(d.train_end_s, color='k', lw=0.6, ls=':')
        ax.set_ylabel(f'tip {name}, {unit}')
    axes[0].legend(loc='lower right', fontsize=8)
    axes[0].set_title('Measured tip against the models (dotted line: end of the fitted part)')
    axes[1].set_xlabel('time, s')
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _residual_figure(d: Diagnosis, path: Path) -> None:
    fig, ax = plt.subplots(figsize=(10, 4))
    r = d.record
    before = (d.before.z - r.z) * 1e6
    after = (d.after.z - r.z) * 1e6
    ax.plot(
        *broken_at_gaps(r.t, before),
        lw=0.7,
        label=f'nominal: rms {d.gap_before.rms_m * 1e6:.1f} um',
    )
    ax.plot(*broken_at_gaps(r.t, after), lw=0.7,
            label=f'augmented: rms {d.gap_after.rms_m * 1e6:.1f} um')  # fmt: skip
    noise = d.noise_z_m * 1e6
    ax.axhspan(-noise, noise, color='0.85', label=f'noise +-{noise:.1f} um')
    ax.axvline(d.train_end_s, color='k', lw=0.6, ls=':')
    ax.set_xlabel('time, s')
    ax.set_ylabel('model - measured z, um')
    ax.set_title(f'Residuals before and after: missing effect = {d.missing_effect}')
    ax.legend(loc='upper right', fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _swing(
    t: np.ndarray, z: np.ndarray, event: float, level: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mid-times, amplitudes and frequencies of a decay, one per full period.

    Each period runs over three successive peaks (both signs): its frequency is the inverse
    of the time between the first and the third, its amplitude the mean of the three
    weighted 1:2:1, which cancels an error in ``level``.
    """
    peak_t, peak_a = decay_peaks(t, z, event, level)  # times between samples
    if peak_t.size < 3:
        return np.empty(0), np.empty(0), np.empty(0)
    period = peak_t[2:] - peak_t[:-2]
    amplitude = 0.25 * (peak_a[:-2] + 2.0 * peak_a[1:-1] + peak_a[2:])
    ok = (period > 0.5 * np.median(period)) & (period < 2.0 * np.median(period))
    return peak_t[1:-1][ok], amplitude[ok], 1.0 / period[ok]


def signature_figure(d: Diagnosis) -> Figure:
    """The signatures that single out the effects, measured against the nominal model.

    Three panels: the time shift at the load event (``sensor_latency``), the frequency
    against the amplitude of the swing (``cubic_stiffness`` drifts with amplitude;
    ``added_mass`` and ``base_compliance`` move it as a whole), and the envelope law of the
    peaks (exponential: viscous only; linear: ``coulomb_friction``; faster at large
    amplitude: ``quadratic_drag``). A panel's title is green when it speaks for an effect
    the diagnosis named.

    Args:
        d: The diagnosis.

    Returns:
        The figure (the caller saves and closes it).
    """
    r, sig = d.record, d.signatures
    event = r.event_time_s
    level = float(np.mean(r.z[r.t >= event + SETTLE_S]))
    named = {name for name, _ in named_effects(d)}
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5))

    ax = axes[0]
    near = (r.t >= event - 0.05) & (r.t <= event + 0.5)
    ax.plot(r.t[near], r.z[near] * 1e3, '.', ms=2, color='0.4', label='measured')
    ax.plot(d.before.t[near], d.before.z[near] * 1e3, lw=1.0, label='nominal')
    shifted = np.interp(r.t[near] - sig.time_shift_s, d.before.t, d.before.z)
    ax.plot(r.t[near], shifted * 1e3, lw=1.0, ls='--', label='nominal, shifted')
    ax.set_title(f'time shift at the load event: {sig.time_shift_s * 1e3:+.1f} ms')
    ax.set_xlabel('time, s')
    ax.set_ylabel('tip z, mm')

    models: tuple[tuple[str, TipTrajectory, str], ...] = (
        ('nominal', d.before, '-'),
        (f'augmented ({d.missing_effect})', d.after, '--'),
    )
    mid_t, amplitude, frequency = _swing(r.t, r.z, event, level)
    axes[1].plot(amplitude * 1e3, frequency, '.', color='0.4', label='measured')
    axes[2].semilogy(mid_t, amplitude * 1e3, '.', color='0.4', label='measured')
    for label, model, style in models:
        m_t, m_amp, m_f = _swing(model.t, model.z, event, level)
        axes[1].plot(m_amp * 1e3, m_f, style, lw=1.0, label=label)
        axes[2].semilogy(m_t, m_amp * 1e3, style, lw=1.0, label=label)
    axes[1].set_title(f'frequency against amplitude (drift {sig.frequency_drift:+.2e})')
    axes[1].set_xlabel('swing amplitude, mm')
    axes[1].set_ylabel('frequency (peak to peak), Hz')
    terms = sig.envelope_terms
    axes[2].set_title(
        f'envelope law: {sig.envelope} (F dry {terms["dry_f"]:.3g}, '
        f'quadratic {terms["quadratic_f"]:.3g})'
    )
    axes[2].set_xlabel('time, s')
    axes[2].set_ylabel('swing amplitude, mm')
    for ax, effects in zip(axes, SIGNATURE_EFFECTS.values(), strict=True):
        speaks = [e for e in effects if e in named]
        ax.set_title(
            f'{", ".join(effects)}\n{ax.get_title()}',
            fontsize=9,
            color='C2' if speaks else 'k',
            fontweight='bold' if speaks else 'normal',
        )
        ax.legend(fontsize=7)
    fig.suptitle(f'Signatures of the residual: missing effect = {d.missing_effect}', fontsize=10)
    fig.tight_layout()
    return fig


def _signature_figure(d: Diagnosis, path: Path) -> None:
    fig = signature_figure(d)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _candidate_figure(d: Diagnosis, path: Path) -> None:
    scores = [d.nominal, *d.candidates]
    names = [s.name for s in scores]
    best = min(s.bic for s in scores)
    # The scores span orders of magnitude: show how far each is above the best one.
    excess = np.array([s.bic - best for s in scores]) + 1.0
    holdout = np.array([s.holdout_chi2 for s in scores])
    fig, axes = plt.subplots(1, 2, figsize=(11, 4))
    colors = [
        'C2' if n == d.missing_effect else ('C3' if not s.physical else 'C0')
        for n, s in zip(names, scores, strict=True)
    ]
    axes[0].barh(names, excess, color=colors)
    axes[0].set_xscale('log')
    axes[0].axvline(11.0, color='k', lw=0.6, ls=':')
    axes[0].set_xlabel('BIC - best BIC + 1 (dotted: significance margin)')
    axes[0].invert_yaxis()
    axes[1].barh(names, holdout, color=colors)
    axes[1].set_xscale('log')
    axes[1].axvline(1.0, color='k', lw=0.6, ls=':')
    axes[1].set_xlabel('held-out chi2 / n (dotted: the noise)')
    axes[1].invert_yaxis()
    title = f'Candidates (green: named, red: unphysical): {d.decision.reason}'
    fig.suptitle(textwrap.fill(title, TITLE_CHARS), fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_diagnosis(d: Diagnosis, folder: str | Path) -> list[Path]:
    """Writes the diagnosis figures as PNG files.

    Args:
        d: The diagnosis.
        folder: Output folder (created when missing).

    Returns:
        The files written, in the order of ``FIGURES``.

    Raises:
        LumpbeamError: The folder cannot be created or written.
    """
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        paths = [folder / name for name in FIGURES]
        for draw, path in zip(
            (_fit_figure, _residual_figure, _signature_figure, _candidate_figure),
            paths,
            strict=True,
        ):
            draw(d, path)
    except OSError as exc:
        raise LumpbeamError(f'cannot write figures to {folder}: {exc.strerror or exc}') from None
    return paths
