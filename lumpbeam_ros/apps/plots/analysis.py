"""Figures of ``lumpbeam analyze``: the decay with its fit, the spectrum, the estimates.

The trajectory figure follows the paper's Fig. B.6: the tip's vertical position through the
drop, here with the fitted decay, its envelope and the release marked.
"""

from __future__ import annotations

import math
from pathlib import Path

import matplotlib

matplotlib.use('Agg')  # before pyplot: files only, no display

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from lumpbeam_ros.apps.plots.files import save_figure  # noqa: E402
from lumpbeam_ros.base.errors import LumpbeamError  # noqa: E402
from lumpbeam_ros.core.ident.identification import Estimate, Identification  # noqa: E402
from lumpbeam_ros.core.ident.samples import PoseWindow  # noqa: E402

#: File names written into the plots folder.
FILES = ('trajectory.png', 'spectrum.png', 'estimates.png')


def _envelope(result: Identification, t: np.ndarray) -> np.ndarray:
    """Amplitude of the fitted first mode about the decay's level (B.20's envelope)."""
    figures = result.estimates
    sigma = figures.damping_ratio.value * 2.0 * math.pi * figures.natural_frequency_hz.value
    return np.asarray(result.quality.amplitude_m * np.exp(-sigma * (t - t[0])))


def plot_trajectory(window: PoseWindow, result: Identification, path: Path) -> None:
    """The tip z over time, the release and the fitted envelope about the level after it.

    Args:
        window: The poses analysed.
        result: The identification.
        path: PNG file to write.
    """
    fig, ax = plt.subplots(figsize=(9, 4.5))
    ax.plot(window.t, 1e3 * window.z, lw=0.6, color='0.35', label='tip z')
    release_s = result.release.time_s.value
    if math.isfinite(release_s):
        ax.axvline(release_s, color='tab:red', ls='--', lw=1, label='release')
    if result.ok and math.isfinite(result.quality.amplitude_m):
        start = release_s if math.isfinite(release_s) else window.start_s
        after = window.t[window.t >= start]
        if after.size:
            level = result.release.level_after_m.value
            env = _envelope(result, after)
            for sign in (1.0, -1.0):
                ax.plot(
                    after,
                    1e3 * (level + sign * env),
                    color='tab:blue',
                    lw=1.2,
                    label='fitted envelope' if sign > 0 else None,
                )
            ax.axhline(1e3 * level, color='tab:blue', lw=0.8, ls=':', label='level after')
    level_before = result.release.level_before_m.value
    if math.isfinite(level_before):
        ax.axhline(1e3 * level_before, color='tab:green', lw=0.8, ls=':')
    ax.set_xlabel('time, s')
    ax.set_ylabel('tip z, mm')
    ax.set_title(
        f'{result.status.name}: f_n {result.estimates.natural_frequency_hz.value:.4f} Hz, '
        f'zeta {result.estimates.damping_ratio.value:.4g}'
    )
    ax.legend(loc='lower right', fontsize=8)
    ax.grid(alpha=0.3)
    _save(fig, path)


def plot_spectrum(window: PoseWindow, result: Identification, path: Path) -> None:
    """Amplitude spectrum of the tip z after the release, with the fitted frequency.

    Args:
        window: The poses analysed.
        result: The identification.
        path: PNG file to write.
    """
    release_s = result.release.time_s.value
    start = release_s if math.isfinite(release_s) else window.start_s
    keep = window.t >= start
    t, z = window.t[keep], window.z[keep]
    fig, ax = plt.subplots(figsize=(7, 4))
    if t.size > 8:
        dt = float(np.median(np.diff(t)))
        grid = np.arange(t[0], t[-1], dt)
        u = np.interp(grid, t, z)
        u = (u - u.mean()) * np.hanning(u.size)
        spectrum = np.abs(np.fft.rfft(u)) * 2.0 / max(np.hanning(u.size).sum(), 1e-12)
        ax.semilogy(np.fft.rfftfreq(u.size, dt), np.maximum(1e3 * spectrum, 1e-12), lw=0.8)
    lines = (
        ('damped_frequency_hz', result.estimates.damped_frequency_hz.value, 'tab:red'),
        ('second_mode_hz', result.quality.second_mode_hz, 'tab:orange'),
    )
    for key, value, style in lines:
        if math.isfinite(value):
            ax.axvline(value, color=style, ls='--', lw=1, label=f'{key} {value:.4g}')
    ax.set_xlabel('frequency, Hz')
    ax.set_ylabel('amplitude, mm (Hann)')
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=8)
    ax.grid(alpha=0.3, which='both')
    _save(fig, path)


def plot_estimates(result: Identification, path: Path) -> None:
    """Each estimate with its cross-checks, as relative deviations with 1-sigma bars.

    Args:
        result: The identification.
        path: PNG file to write.
    """
    figures, checks = result.estimates, result.cross_checks
    rows = [
        ('f_n: fit', figures.natural_frequency_hz, 'f'),
        ('f_n: matrix pencil', Estimate(checks.natural_frequency_pencil_hz), 'f'),
        ('zeta: fit', figures.damping_ratio, 'z'),
        ('zeta: log decrement B.21', checks.damping_ratio_b20, 'z'),
        ('zeta: matrix pencil', Estimate(checks.damping_ratio_pencil), 'z'),
        ('k_tE: static B.12', figures.stiffness_total_nm_per_rad, 'k'),
        ('k_tE: pitch', checks.stiffness_total_from_pitch_nm_per_rad, 'k'),
    ]
    reference = {
        'f': figures.natural_frequency_hz.value,
        'z': figures.damping_ratio.value,
        'k': figures.stiffness_total_nm_per_rad.value,
    }
    fig, ax = plt.subplots(figsize=(7, 4))
    for i, (_, estimate, group) in enumerate(rows):
        value, std, ref = estimate.value, estimate.std, reference[group]
        if not (math.isfinite(value) and math.isfinite(ref) and ref != 0.0):
            continue
        err = 100.0 * std / abs(ref) if math.isfinite(std) else 0.0
        ax.errorbar(100.0 * (value / ref - 1.0), i, xerr=err, fmt='o', capsize=3)
    ax.set_yticks(range(len(rows)), [r[0] for r in rows])
    ax.axvline(0.0, color='0.5', lw=0.8)
    ax.set_xlabel('deviation from the headline estimate, % (bars: 1 sigma)')
    ax.invert_yaxis()
    ax.grid(alpha=0.3)
    _save(fig, path)


def write_analysis_plots(window: PoseWindow, result: Identification, folder: Path) -> list[Path]:
    """Writes the three figures into ``folder`` (created when missing).

    Args:
        window: The poses analysed.
        result: The identification.
        folder: Output folder.

    Returns:
        The files written (:data:`FILES`).

    Raises:
        LumpbeamError: The folder cannot be created or written.
    """
    folder = Path(folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise LumpbeamError(f'cannot create plots folder {folder}: {exc.strerror}') from None
    paths = [folder / name for name in FILES]
    plot_trajectory(window, result, paths[0])
    plot_spectrum(window, result, paths[1])
    plot_estimates(result, paths[2])
    return paths


def _save(fig: Figure, path: Path) -> None:
    try:
        fig.tight_layout()
        save_figure(fig, path, dpi=110)
    finally:
        plt.close(fig)
