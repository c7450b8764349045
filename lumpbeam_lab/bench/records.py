"""Any record's modes beside peers on the same records: accuracy, coverage and speed.

The product (:func:`~lumpbeam_ros.core.ident.free_vibration.analyze_record`) finds the free
vibration itself; the peers are given the true one (from 5 ms after the tap to the end), as a
user who looked at the record would cut it:

- ``fft_logdec``: a plain FFT peak (zero-padded, parabolic) nearest each true mode, and the
  log decrement of the Hilbert envelope of the record band-passed around it (its fall from
  80 % to 20 % of its top);
- ``era``: pyyeti's :class:`pyyeti.era.ERA` (automatic mode selection, up to 1000 block rows
  and columns: the first 2000 samples);
- ``ssi_cov``: :func:`~lumpbeam_lab.ident.ssi_cov.ssi_cov_modes` (pyOMA2 does not install).

A peer's mode is the one nearest a true mode within 5 % of its frequency, else a miss.

Synthetic rows (``records_<kind>``): a lab's records with a known truth, over seeded trials:
a tapped steel cantilever with an accelerometer and mains hum, a beam struck and filmed at
15 kHz, a structure at half a hertz, a 1.79 Hz ring in 1 mm steps, a record clipped by its
sensor. Each gives, per method, the RMS of the damping ratio's relative error over every true
mode and trial (bias included; misses counted apart) and the frequency's; for the product
also the fraction of its estimates within 3 of its own standard deviations (the coverage).
The row's value is the product's damping RMS, its baseline the best peer's.

Measured rows: three shocks of one circuit board (``test/data/records``): how far apart each
method puts the trials' strongest mode (they should agree); the shaker still running: the
"modes" each method reports in a record that has none (the product: lines).

Speed rows: the CPU time of the product on a 50 s, 1.65 kHz record of three modes and on a
0.25 s, 15 kHz one, against a plain FFT and log decrement's of the same modes (ERA's SVD of
the whole record would need 50 GB); the targets (1 s and 0.5 s) beside.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.signal import butter, hilbert, sosfiltfilt

from lumpbeam_lab.bench.bench_result import BenchResult
from lumpbeam_lab.ident.ssi_cov import ssi_cov_modes
from lumpbeam_lab.ident.taps import RECORDS, Tap
from lumpbeam_ros.base.blas import single_threaded_blas
from lumpbeam_ros.core.ident.free_vibration import analyze_record
from lumpbeam_ros.core.ident.settings import IdentifierConfig
from lumpbeam_ros.core.records.labfile import ChannelChoice, read_lab_file

#: The speed rows' records and their targets, CPU s.
SPEED = {
    'records_speed_50s_1650hz': (
        Tap(1650, 50, (0.5,), ((6.62, 0.002, 10.0), (41.4, 0.002, 5.0), (117.5, 0.002, 3.0)),
            noise=0.02),
        1.0,
    ),
    'records_speed_0.25s_15khz': (RECORDS['struck_beam_15khz'], 0.5),
}  # fmt: skip
#: Where the measured records are (the repository's test data).
MEASURED = Path(__file__).resolve().parents[2] / 'test' / 'data' / 'records'
#: A peer's mode matches a true one within this fraction of its frequency.
MATCH = 0.05
#: The peers' stretch starts this long after the tap (past the hammer's contact).
AFTER_TAP_S = 0.005
#: ERA's block rows and columns at most.
ERA_BLOCKS = 1000
#: Trials per synthetic record.
SEEDS = 30

#: ``(natural frequency Hz, damping ratio)`` of the modes a method finds in ``(t, y)``.
Method = Callable[[np.ndarray, np.ndarray], list[tuple[float, float]]]


def fft_logdec(t: np.ndarray, y: np.ndarray, near: list[float]) -> list[tuple[float, float]]:
    """A plain FFT peak near each frequency and the log decrement of its band's envelope."""
    rate = 1.0 / float(np.median(np.diff(t)))
    n_fft = 1 << int(math.ceil(math.log2(8 * y.size)))
    spectrum = np.abs(np.fft.rfft((y - y.mean()) * np.hanning(y.size), n_fft))
    found = []
    for f0 in near:
        lo, hi = (int(f0 * (1 - MATCH) * n_fft / rate), int(f0 * (1 + MATCH) * n_fft / rate) + 1)
        if hi - lo < 3 or hi >= spectrum.size:
            continue
        k = lo + int(np.argmax(spectrum[lo:hi]))
        a, b, c = np.log(spectrum[k - 1 : k + 2])
        f = (k + 0.5 * (a - c) / (a - 2 * b + c)) * rate / n_fft
        band = butter(2, [f * (1 - MATCH), min(f * (1 + MATCH), 0.49 * rate)], 'bandpass',
                      fs=rate, output='sos')  # fmt: skip
        envelope = np.abs(hilbert(sosfiltfilt(band, y - y.mean())))
        top = int(np.argmax(envelope))
        fall = envelope[top:]
        keep = (fall < 0.8 * fall[0]) & (fall > 0.2 * fall[0])
        if keep.sum() < 8:
            continue
        sigma = -np.polyfit(t[top:][keep], np.log(fall[keep]), 1)[0]
        found.append((f, sigma / (2 * math.pi * f)))
    return found


def era_modes(t: np.ndarray, y: np.ndarray) -> list[tuple[float, float]]:
    """pyyeti's ERA on the stretch's first samples, modes selected automatically.

    Its Hankel matrix takes up to 1000 block rows and columns (the first 2000 samples): its
    SVD grows with the cube of that, and a whole 50 s record would need 50 GB.
    """
    from pyyeti.era import ERA

    rate = 1.0 / float(np.median(np.diff(t)))
    size = min(ERA_BLOCKS, y.size // 2)
    try:
        with single_threaded_blas():
            era = ERA(y - y.mean(), rate, svd_tol=16, auto=True, verbose=False,
                      show_plot=False, alpha=size, beta=size)  # fmt: skip
    except RuntimeError:  # "No modes selected"
        return []
    return [
        (float(f), float(z))
        for f, z in zip(np.atleast_1d(era.freqs_hz), np.atleast_1d(era.zeta), strict=True)
    ]


def ssi_modes(t: np.ndarray, y: np.ndarray) -> list[tuple[float, float]]:
    """SSI-cov on the stretch, order 16, 200 block rows (fewer in a short record)."""
    rate = 1.0 / float(np.median(np.diff(t)))
    with single_threaded_blas():
        return ssi_cov_modes(y, rate, order=16, block_rows=min(200, y.size // 4))


def _match(found: list[tuple[float, float]], f: float) -> tuple[float, float] | None:
    near = [m for m in found if abs(m[0] - f) <= MATCH * f and 0.0 < m[1] < 1.0]
    return min(near, key=lambda m: abs(m[0] - f)) if near else None


@dataclass
class _Tally:
    """One method's relative errors over every true mode and trial."""

    f: list[float]
    zeta: list[float]
    misses: int = 0
    within: int = 0

    def add(self, mode: tuple[float, float] | None, truth: tuple[float, float, float]) -> None:
        if mode is None:
            self.misses += 1
            return
        self.f.append(mode[0] / truth[0] - 1.0)
        self.zeta.append(mode[1] / truth[1] - 1.0)

    def figures(self, prefix: str) -> dict[str, float]:
        out: dict[str, float] = {f'{prefix}_misses': float(self.misses)}
        for name, errors in (('f', self.f), ('zeta', self.zeta)):
            e = np.asarray(errors)
            if e.size:
                out.update({
                    f'{prefix}_{name}_rel_rms': float(np.sqrt(np.mean(e**2))),
                    f'{prefix}_{name}_rel_bias': float(np.mean(e)),
                    f'{prefix}_{name}_rel_std': float(np.std(e)),
                    f'{prefix}_{name}_rel_max': float(np.max(np.abs(e))),
                })  # fmt: skip
        return out


def synthetic_row(name: str, tap: Tap, seeds: int) -> BenchResult:
    """The product and the peers on one kind of record over seeded trials."""
    methods = ('lumpbeam', 'fft_logdec', 'era', 'ssi_cov')
    tallies = {m: _Tally([], []) for m in methods}
    estimates = 0
    config = IdentifierConfig()
    for seed in range(seeds):
        t, y = tap.record(seed)
        modes = analyze_record(t, y, config).identification.modes
        after = t >= tap.taps_s[0] + AFTER_TAP_S
        ts, ys = t[after], y[after]
        truths = [m[0] for m in tap.modes]
        peers = {
            'fft_logdec': fft_logdec(ts, ys, truths),
            'era': era_modes(ts, ys),
            'ssi_cov': ssi_modes(ts, ys),
        }
        for truth in tap.modes:
            ours = [m for m in modes if abs(m.natural_frequency_hz.value / truth[0] - 1) < MATCH]
            mode = ours[0] if ours else None
            tallies['lumpbeam'].add(
                None if mode is None else (mode.natural_frequency_hz.value,
                                           mode.damping_ratio.value), truth)  # fmt: skip
            if mode is not None:
                estimates += 2
                for est, true in ((mode.natural_frequency_hz, truth[0]),
                                  (mode.damping_ratio, truth[1])):  # fmt: skip
                    tallies['lumpbeam'].within += abs(est.value - true) <= 3 * est.std
            for peer, found in peers.items():
                tallies[peer].add(_match(found, truth[0]), truth)
    details: dict[str, float] = {'trials': float(seeds), 'modes': float(len(tap.modes))}
    for method, tally in tallies.items():
        details.update(tally.figures(method))
    details['lumpbeam_within_3_std'] = tallies['lumpbeam'].within / max(estimates, 1)
    ours = details.get('lumpbeam_zeta_rel_rms', math.inf)
    best_peer = min((details.get(f'{p}_zeta_rel_rms', math.inf), p) for p in methods[1:])
    return BenchResult(
        f'records_{name}', ours, 'zeta rel RMS', f'best peer ({best_peer[1]})', best_peer[0],
        best_peer[0] / ours if ours > 0 else math.inf, details,
    )  # fmt: skip


def shock_row() -> BenchResult:
    """Three measured shocks of one board: how far apart each method puts its mode."""
    config = IdentifierConfig()
    found: dict[str, list[tuple[float, float]]] = {m: [] for m in ('lumpbeam', 'fft_logdec',
                                                                   'era', 'ssi_cov')}  # fmt: skip
    stds = []
    for trial in (0, 10, 20):
        record = read_lab_file(
            MEASURED / f'pcb_shock_acc_pcb_a{trial}.txt',
            ChannelChoice(column='acceleration(g)', time_column='time(s)'),
        )
        t, y = record.t, record.values * 9.80665
        result = analyze_record(t, y, config)
        head = result.identification.modes[0]
        found['lumpbeam'].append((head.natural_frequency_hz.value, head.damping_ratio.value))
        stds.append((head.natural_frequency_hz.std, head.damping_ratio.std))
        start = result.events[0].event.start_s
        ts, ys = t[t >= start], y[t >= start]
        ours = found['lumpbeam'][-1][0]
        peers = {
            'fft_logdec': fft_logdec(ts, ys, [ours]),
            'era': era_modes(ts, ys),
            'ssi_cov': ssi_modes(ts, ys),
        }
        for peer, modes in peers.items():
            mode = _match(modes, ours)
            found[peer].append(mode if mode is not None else (math.nan, math.nan))
    details: dict[str, float] = {}
    for method, modes in found.items():
        f, zeta = np.array(modes).T
        details[f'{method}_f_hz_mean'] = float(np.mean(f))
        details[f'{method}_f_spread_hz'] = float(np.std(f))
        details[f'{method}_zeta_mean'] = float(np.mean(zeta))
        details[f'{method}_zeta_spread'] = float(np.std(zeta))
    details['lumpbeam_f_std_median_hz'] = float(np.median([s[0] for s in stds]))
    details['lumpbeam_zeta_std_median'] = float(np.median([s[1] for s in stds]))
    ours = details['lumpbeam_zeta_spread']
    peers = [(details[f'{p}_zeta_spread'], p) for p in ('fft_logdec', 'era', 'ssi_cov')]
    best = min((v, p) for v, p in peers if math.isfinite(v))
    return BenchResult(
        'records_pcb_shock_trials', ours, 'zeta spread', f'best peer ({best[1]})', best[0],
        best[0] / ours if ours > 0 else math.inf, details,
    )  # fmt: skip


def shaker_row() -> BenchResult:
    """The shaker still running: lines for the product, the modes the peers report."""
    record = read_lab_file(
        MEASURED / 'shaker_cantilever_test3_400hz.lvm', ChannelChoice(column='Acceleration')
    )
    t, y = record.t, record.values * 9.80665
    result = analyze_record(t, y, IdentifierConfig())
    details: dict[str, object] = {
        'lumpbeam_status': result.identification.status.name,
        'lumpbeam_modes': [m.natural_frequency_hz.value for m in result.identification.modes],
        'lumpbeam_lines_hz': sorted(line.frequency_hz for line in result.lines),
        'era_modes_hz': sorted(f for f, _ in era_modes(t, y)),
        'ssi_cov_modes_hz': sorted(f for f, _ in ssi_modes(t, y)),
    }
    wrong = max(len(details['era_modes_hz']), len(details['ssi_cov_modes_hz']))  # type: ignore[arg-type]
    ours = len(result.identification.modes)
    # One more than each count: a ratio of the two however many none reports.
    return BenchResult(
        'records_shaker_running', float(ours), 'modes reported (none exist)',
        'the peer reporting most', float(wrong), (wrong + 1) / (ours + 1), details,
    )  # fmt: skip


def speed_row(name: str, tap: Tap, target_s: float) -> BenchResult:
    """The product's CPU time on a record against a plain FFT and log decrement's."""
    t, y = tap.record()
    config = IdentifierConfig()
    with single_threaded_blas():
        start = time.process_time()
        result = analyze_record(t, y, config)
        ours = time.process_time() - start
        start = time.process_time()
        fft_logdec(t, y, [m[0] for m in tap.modes])
        plain = time.process_time() - start
    details = {
        'samples': float(t.size),
        'modes_found': float(len(result.identification.modes)),
        'target_cpu_s': target_s,
        'target_met': ours < target_s,
    }
    return BenchResult(name, ours, 'CPU s', 'FFT peak + log decrement', plain, plain / ours,
                       details)  # fmt: skip


def run(quick: bool = False) -> list[BenchResult]:
    """Every row.

    Args:
        quick: Two trials per synthetic record instead of :data:`SEEDS`.
    """
    seeds = 2 if quick else SEEDS
    rows = [synthetic_row(name, tap, seeds) for name, tap in RECORDS.items()]
    rows += [shock_row(), shaker_row()]
    rows += [speed_row(name, tap, target) for name, (tap, target) in SPEED.items()]
    return rows
