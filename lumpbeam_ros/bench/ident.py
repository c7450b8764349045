"""Identifier speed: batch throughput and the live window's update cost, against baselines.

The input is a synthetic drop record (a two-mode free decay after a B.12 static step, with
20 micrometres of white noise at 180 Hz), so both sides see the same data. The baselines are
what a first implementation would do: walk the samples in Python to find the release, then
``scipy.optimize.curve_fit`` a damped sinusoid from an FFT-bin frequency and zero damping,
with finite-difference Jacobians; live, keep the poses in a Python list and rebuild arrays
from it on every update.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
from scipy.optimize import curve_fit

from lumpbeam_ros.bench.result import BenchResult, best_time
from lumpbeam_ros.ident.config import IdentifierConfig
from lumpbeam_ros.ident.identify import identify
from lumpbeam_ros.ident.samples import clean_window
from lumpbeam_ros.ident.window import SlidingWindow
from lumpbeam_ros.model.parameters import BeamParameters

RATE_HZ = 180.0
RELEASE_S = 2.0
F_HZ = 3.07
ZETA = 0.0024
NOISE_M = 20e-6


def synthetic_record(
    duration_s: float, beam: BeamParameters, seed: int = 0
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A drop record: rest under 4.5 kg, release at 2 s, free decay (not a beam model).

    Args:
        duration_s: Record length.
        beam: Supplies L, k_tE and g for the B.12 static step.
        seed: Noise seed.

    Returns:
        Stamps, tip z and tip pitch.
    """
    t = np.arange(0.0, duration_s, 1.0 / RATE_HZ)
    step = 4.5 * beam.gravity_mps2 * 2.0 * beam.length_m**2 / (3.0 * beam.k_total_nm_per_rad)
    tau = np.maximum(t - RELEASE_S, 0.0)
    shape = np.zeros_like(t)
    for share, f_hz, zeta in ((0.99, F_HZ, ZETA), (0.01, 25.0, ZETA * 25.0 / F_HZ)):
        wn = 2.0 * math.pi * f_hz
        sigma, wd = zeta * wn, wn * math.sqrt(1.0 - zeta * zeta)
        shape += share * np.exp(-sigma * tau) * (np.cos(wd * tau) + sigma / wd * np.sin(wd * tau))
    exact = -0.05 + step * (1.0 - shape)
    rng = np.random.default_rng(seed)
    z = exact + rng.normal(0.0, NOISE_M, t.size)
    pitch = -1.5 * exact / beam.length_m + rng.normal(0.0, 1e-5, t.size)
    return t, z, pitch


def _decay_model(t: np.ndarray, c: float, a: float, s: float, w: float, p: float) -> np.ndarray:
    return c + a * np.exp(-s * t) * np.cos(w * t + p)


def baseline_identify(
    t: list[float] | np.ndarray, z: list[float] | np.ndarray, beam: BeamParameters
) -> dict[str, float]:
    """A straightforward identification: Python loops and ``curve_fit`` from a naive start.

    Args:
        t: Stamps.
        z: Tip z.
        beam: Supplies L and g.

    Returns:
        Natural frequency, damping ratio and k_tE.
    """
    first = [z[i] for i in range(min(100, len(z)))]
    mean0 = sum(first) / len(first)
    noise = math.sqrt(sum((v - mean0) ** 2 for v in first) / len(first))
    release = 0
    for i in range(len(z) - 3):
        if all(abs(z[i + k] - mean0) > 6.0 * noise for k in range(3)):
            release = i
            break
    before = sum(z[:release]) / max(release, 1)
    t_after = np.asarray(t[release:]) - t[release]
    z_after = np.asarray(z[release:])
    spectrum = np.abs(np.fft.rfft(z_after - z_after.mean()))
    freqs = np.fft.rfftfreq(z_after.size, float(np.median(np.diff(t_after))))
    f0 = float(freqs[1 + int(np.argmax(spectrum[1:]))])
    p0 = [float(z_after.mean()), float(np.ptp(z_after) / 2), 0.0, 2.0 * math.pi * f0, math.pi]
    popt, _ = curve_fit(_decay_model, t_after, z_after, p0=p0, maxfev=20000)
    c, _, s, w, _ = popt
    wn = math.hypot(s, w)
    delta = c - before
    force = 4.5 * beam.gravity_mps2
    return {
        'natural_frequency_hz': wn / (2.0 * math.pi),
        'damping_ratio': s / wn,
        'stiffness_total_nm_per_rad': 2.0 * force * beam.length_m**2 / (3.0 * delta),
    }


def _errors(found: dict[str, float], beam: BeamParameters) -> dict[str, float]:
    truth = {
        'natural_frequency_hz': F_HZ,
        'damping_ratio': ZETA,
        'stiffness_total_nm_per_rad': beam.k_total_nm_per_rad,
    }
    return {f'{key}_rel_error': abs(found[key] / value - 1.0) for key, value in truth.items()}


def _batch(quick: bool, beam: BeamParameters) -> BenchResult:
    duration = 30.0 if quick else 120.0
    t, z, pitch = synthetic_record(duration, beam)
    config = IdentifierConfig(max_fit_s=duration)
    window = clean_window(t, z, pitch)
    ours_s, result = best_time(lambda: identify(clean_window(t, z, pitch), beam, config))
    base_s, base = best_time(lambda: baseline_identify(t.tolist(), z.tolist(), beam), repeat=1)
    ours = _errors(result.as_dict(), beam)
    theirs = _errors(base, beam)
    value, baseline_value = len(window) / ours_s, len(window) / base_s
    details: dict[str, object] = {'samples': len(window), 'status': result.status.name}
    details.update({f'ours_{k}': v for k, v in ours.items()})
    details.update({f'baseline_{k}': v for k, v in theirs.items()})
    return BenchResult(
        name='ident_batch_throughput',
        value=value,
        unit='samples/s',
        baseline='python-loop release + curve_fit(naive p0, 2-point jac)',
        baseline_value=baseline_value,
        ratio=value / baseline_value,
        details=details,
    )


def _live(quick: bool, beam: BeamParameters) -> BenchResult:
    t, z, pitch = synthetic_record(11.0, beam, seed=1)
    config = IdentifierConfig()
    window = SlidingWindow.from_config(config)
    poses: list[tuple[float, float, float]] = []
    push_s, _ = best_time(lambda: _fill(window, t, z, pitch), repeat=1)
    for row in zip(t.tolist(), z.tolist(), pitch.tolist(), strict=True):
        poses.append(row)
    repeat = 5 if quick else 30

    def ours() -> object:
        return identify(window.snapshot(), beam, config)

    def baseline() -> object:
        newest = max(p[0] for p in poses)
        kept = sorted(p for p in poses if p[0] >= newest - config.window_s)
        return baseline_identify([p[0] for p in kept], [p[1] for p in kept], beam)

    ours_s, result = best_time(ours, repeat=repeat)
    base_s, _ = best_time(baseline, repeat=max(1, repeat // 10))
    return BenchResult(
        name='ident_window_update_10s_180hz',
        value=1e3 * ours_s,
        unit='ms/update',
        baseline='python list + curve_fit(naive p0) per update',
        baseline_value=1e3 * base_s,
        ratio=base_s / ours_s,
        details={
            'samples': len(window.snapshot()),
            'status': result.status.name,
            'push_us_per_sample': 1e6 * push_s / t.size,
        },
    )


def _fill(window: SlidingWindow, t: np.ndarray, z: np.ndarray, pitch: np.ndarray) -> None:
    push: Callable[[float, float, float], bool] = window.push
    for row in zip(t.tolist(), z.tolist(), pitch.tolist(), strict=True):
        push(*row)


def run(quick: bool = False) -> list[BenchResult]:
    """Runs the identifier benchmarks.

    Args:
        quick: A 30 s record instead of 120 s, and fewer repeats.

    Returns:
        The batch-throughput and window-update results.
    """
    beam = BeamParameters()
    return [_batch(quick, beam), _live(quick, beam)]
