"""Figures of a diagnosis: the fits, the residuals before and after, the candidates' scores."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use('Agg')  # files only: no display on a robot or a CI runner

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from lumpbeam_ros.diagnose.workflow import Diagnosis  # noqa: E402
from lumpbeam_ros.errors import LumpbeamError  # noqa: E402

#: The files :func:`plot_diagnosis` writes.
FIGURES = ('diagnosis_fit.png', 'diagnosis_residuals.png', 'diagnosis_candidates.png')


def _fit_figure(d: Diagnosis, path: Path) -> None:
    fig, axes = plt.subplots(2, 1, figsize=(10, 6), sharex=True)
    r = d.record
    label_after = f'augmented ({d.missing_effect})'
    for ax, name, scale, unit in ((axes[0], 'z', 1e3, 'mm'), (axes[1], 'pitch', 1e3, 'mrad')):
        ax.plot(r.t, getattr(r, name) * scale, '.', ms=1.5, color='0.5', label='measured')
        ax.plot(d.before.t, getattr(d.before, name) * scale, lw=1.0, label='nominal (refit)')
        ax.plot(d.after.t, getattr(d.after, name) * scale, lw=1.0, ls='--', label=label_after)
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
    ax.plot(r.t, before, lw=0.7, label=f'nominal: rms {d.gap_before.rms_m * 1e6:.1f} um')
    ax.plot(r.t, after, lw=0.7, label=f'augmented: rms {d.gap_after.rms_m * 1e6:.1f} um')
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
    fig.suptitle(f'Candidates (green: named, red: unphysical): {d.decision.reason}', fontsize=8)
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
            (_fit_figure, _residual_figure, _candidate_figure), paths, strict=True
        ):
            draw(d, path)
    except OSError as exc:
        raise LumpbeamError(f'cannot write figures to {folder}: {exc.strerror or exc}') from None
    return paths
