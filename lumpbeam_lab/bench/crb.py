"""Identifier against the Cramér-Rao bound: frequency and damping of one damped sinusoid.

The data: the nonlinear lumped model's drop test (the configured beam, 4.5 kg released at
2 s, 12 s at 180 Hz) with white pose noise of 20 um, 200 um and 1 mm, over seeded trials.
The truth: the first mode of the unloaded chain (frequency and damping ratio).

The bound, computed in the same run: the tip z after the release modelled as one damped
sinusoid plus an offset, ``z = c + A exp(-zeta w t) cos(w sqrt(1 - zeta^2) t + p)``,
``w = 2 pi f``, at the identified parameters (the first trial's ``f`` and ``zeta``; the
amplitude and phase of a beam released from rest, the offset irrelevant to the bound), in
white noise of the level's sigma over every sample from the release to the end. Its Fisher
information is ``J^T J / sigma^2`` (``J``: the model's derivatives in ``(c, A, zeta, f, p)``,
by central differences); the bound on a parameter's standard deviation is the square root
of that diagonal element of the inverse. An efficient unbiased estimator errs by about the
bound; the ratio of each row is the bound over the identifier's RMS error (1 at the bound).

Each row reports, per level: the identifier's RMS error of ``f`` (bias included) against the
bound, and beside it the bias, the standard deviation and the largest error, the same for
``zeta``, and the median of the identifier's own reported standard deviations (whether they
hold: the RMS error in units of them).
"""

from __future__ import annotations

import math

import numpy as np

from lumpbeam_lab.bench.bench_result import BenchResult
from lumpbeam_lab.bench.ident import model_truth
from lumpbeam_ros.ident.identify import identify
from lumpbeam_ros.ident.samples import clean_window
from lumpbeam_ros.ident.settings import IdentifierConfig
from lumpbeam_ros.model.parameters import DropTestConfig, load_beam_config
from lumpbeam_ros.model.simulate import simulate_drop_test
from lumpbeam_ros.model.statics import static_tip_deflection

RATE_HZ = 180.0
LOAD_KG = 4.5
RELEASE_S = 2.0
DURATION_S = 12.0
#: Pose noise levels, m (and rad for the pitch).
LEVELS_M = (20e-6, 200e-6, 1e-3)
SEEDS = 5


def damped_sinusoid(t: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """``c + A exp(-zeta w t) cos(w sqrt(1 - zeta^2) t + p)``, ``theta = (c, A, zeta, f, p)``."""
    c, a, zeta, f, p = theta
    w = 2.0 * math.pi * f
    return np.asarray(c + a * np.exp(-zeta * w * t) * np.cos(w * math.sqrt(1.0 - zeta**2) * t + p))


def cramer_rao(t: np.ndarray, theta: np.ndarray, sigma: float) -> np.ndarray:
    """Standard-deviation bounds of ``theta`` for :func:`damped_sinusoid` in white noise.

    Args:
        t: Sample times from the release, s.
        theta: ``(c, A, zeta, f, p)``.
        sigma: Noise standard deviation, m.

    Returns:
        The bound on each parameter's standard deviation, same order.
    """
    columns = []
    for i, value in enumerate(theta):
        step = 1e-6 * max(abs(float(value)), 1e-3)
        up, down = np.array(theta, dtype=float), np.array(theta, dtype=float)
        up[i] += step
        down[i] -= step
        columns.append((damped_sinusoid(t, up) - damped_sinusoid(t, down)) / (2.0 * step))
    jacobian = np.column_stack(columns)
    fisher = jacobian.T @ jacobian / sigma**2
    return np.asarray(np.sqrt(np.diag(np.linalg.inv(fisher))))


def _spread(errors: np.ndarray) -> dict[str, float]:
    return {
        'rms': float(np.sqrt(np.mean(errors**2))),
        'bias': float(np.mean(errors)),
        'std': float(np.std(errors)),
        'max': float(np.max(np.abs(errors))),
    }


def level_row(sigma: float, seeds: int) -> BenchResult:
    """The identifier's frequency and damping errors at one noise level against the bound.

    Args:
        sigma: Pose noise, m.
        seeds: Trials.

    Returns:
        The ``crb_<level>`` row.
    """
    beam, _ = load_beam_config()
    truth = model_truth(beam)
    exact = simulate_drop_test(beam, DropTestConfig(LOAD_KG, RELEASE_S, DURATION_S), RATE_HZ)
    config = IdentifierConfig(max_fit_s=DURATION_S)
    found: dict[str, list[float]] = {k: [] for k in ('f', 'f_std', 'zeta', 'zeta_std')}
    for seed in range(seeds):
        rng = np.random.default_rng(1000 + seed)
        z = exact.z + rng.normal(0.0, sigma, len(exact))
        pitch = exact.pitch + rng.normal(0.0, sigma, len(exact))
        result = identify(clean_window(exact.t, z, pitch), beam, config, strict=True).as_dict()
        found['f'].append(result['natural_frequency_hz'])
        found['f_std'].append(result['natural_frequency_hz_std'])
        found['zeta'].append(result['damping_ratio'])
        found['zeta_std'].append(result['damping_ratio_std'])
    f, zeta = found['f'][0], found['zeta'][0]
    # Released from rest: z = c + A0 e^{-s t} (cos w_d t + s/w_d sin w_d t) = A cos(w_d t + p).
    amplitude0 = static_tip_deflection(beam, LOAD_KG) - static_tip_deflection(beam, 0.0)
    ratio = zeta / math.sqrt(1.0 - zeta**2)
    theta = np.array([0.0, amplitude0 * math.hypot(1.0, ratio), zeta, f, -math.atan(ratio)])
    t = exact.t[exact.t >= RELEASE_S] - RELEASE_S
    bound = cramer_rao(t, theta, sigma)
    f_err = _spread(np.asarray(found['f']) - truth['natural_frequency_hz'])
    zeta_err = _spread(np.asarray(found['zeta']) - truth['damping_ratio'])
    f_bound, zeta_bound = float(bound[3]), float(bound[2])
    return BenchResult(
        name=f'crb_{sigma * 1e6:g}um',
        value=f_err['rms'],
        unit='Hz RMS error of f',
        baseline='Cramér-Rao bound of f (one damped sinusoid, white noise)',
        baseline_value=f_bound,
        ratio=f_bound / f_err['rms'],
        details={
            'noise_m': sigma,
            'trials': seeds,
            'f_truth_hz': truth['natural_frequency_hz'],
            'f_error_bias_hz': f_err['bias'],
            'f_error_std_hz': f_err['std'],
            'f_error_max_hz': f_err['max'],
            'f_rms_over_bound': f_err['rms'] / f_bound,
            'f_reported_std_median_hz': float(np.median(found['f_std'])),
            'f_rms_in_reported_std': f_err['rms'] / float(np.median(found['f_std'])),
            'zeta_truth': truth['damping_ratio'],
            'zeta_error_rms': zeta_err['rms'],
            'zeta_error_bias': zeta_err['bias'],
            'zeta_error_std': zeta_err['std'],
            'zeta_error_max': zeta_err['max'],
            'zeta_bound': zeta_bound,
            'zeta_rms_over_bound': zeta_err['rms'] / zeta_bound,
            'zeta_reported_std_median': float(np.median(found['zeta_std'])),
            'zeta_rms_in_reported_std': zeta_err['rms'] / float(np.median(found['zeta_std'])),
        },
    )


def run(quick: bool = False) -> list[BenchResult]:
    """Runs every noise level.

    Args:
        quick: Two trials per level instead of five.

    Returns:
        One row per level, 20 um first.
    """
    return [level_row(sigma, 2 if quick else SEEDS) for sigma in LEVELS_M]
