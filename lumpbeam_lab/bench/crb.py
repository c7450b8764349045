"""Identifier and peers against the Cramér-Rao bound: frequency and damping of the first mode.

The data: the nonlinear lumped model's drop test (the configured beam, 4.5 kg released at
2 s, 12 s at 180 Hz) with white pose noise of 20 um, 200 um and 1 mm, over seeded trials;
then the same in MuJoCo (the chain in MuJoCo's own multibody dynamics, which shares none of
the product's code). The truth: the first mode of the unloaded chain (frequency and damping
ratio), the small-amplitude limit (MuJoCo's from its own linearization).

Three bounds, computed in the same run, all for the tip z from the release to the end in
white noise of the level's sigma (Fisher information ``J^T J / sigma^2``, ``J`` by central
differences; the bound on a parameter's standard deviation is the square root of that
diagonal element of the inverse):

- *linear*: one damped sinusoid plus an offset,
  ``z = c + A exp(-zeta w t) cos(w sqrt(1 - zeta^2) t + p)``, ``w = 2 pi f``, with the
  amplitude and phase of a beam released from rest. An unbiased estimator reaches it only
  if the oscillation is linear.
- *nonlinear*: the same with the first mode's amplitude-dependent level and frequency
  unknown (:mod:`lumpbeam_ros.core.ident.sinusoid`, ``nonlinear``): ``+ e exp(-2 zeta w t)`` and
  the phase ``+ 2 pi q (1 - exp(-2 zeta w t)) / (2 zeta w)``, at the identified ``e`` and
  ``q``. The beam's frequency depends on its amplitude (the drop's 4 cm make it about 8 ppm
  fast), so an estimator of the small-amplitude frequency that does not know how much is
  bounded by this one; a linear fit is as precise as the linear bound but biased by the
  amplitude-averaged shift.
- *backbone*: the nonlinear one with what the identifier knows by default, the beam
  model's backbone (:mod:`lumpbeam_ros.core.ident.backbone`) as a prior on the shift,
  ``q = gamma f A^2`` give or take ``fit.shift_prior_std`` of it (a Bayesian bound: the
  prior's information added to the data's). It lies between the other two.

Peers on the same samples (from 20 ms after the release to the end, the identifier's):
ERA (pyyeti's :class:`pyyeti.era.ERA`, a benchmark-only dependency) and covariance-driven
SSI (:func:`~lumpbeam_lab.ident.ssi_cov.ssi_cov_modes`; pyOMA2 does not install here).

Each row reports, per level: the identifier's RMS error of ``f`` (bias included) against
the linear bound, and beside it the bias, the standard deviation and the largest error, the
other bounds, the identifier with the shift fitted freely (``free_shift_``, the default
before the backbone) and with ``fit.nonlinear`` never (``linear_``), the peers' RMS
errors, the same for ``zeta``, the median of the identifier's own reported standard
deviations (whether they hold: the RMS error in units of them) and the fraction of trials
whose truth lies within 3 of them. The levels scale the same seeded noise, so their ratios
are alike by construction, not three confirmations.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from lumpbeam_lab.bench.bench_result import BenchResult
from lumpbeam_lab.bench.ident import model_truth
from lumpbeam_lab.ident.ssi_cov import ssi_cov_modes
from lumpbeam_lab.mujoco_arm import mujoco_drop_test
from lumpbeam_ros.base.blas import single_threaded_blas
from lumpbeam_ros.core.ident.backbone import beam_backbone
from lumpbeam_ros.core.ident.identify import identify
from lumpbeam_ros.core.ident.samples import PoseWindow, clean_window
from lumpbeam_ros.core.ident.settings import IdentifierConfig
from lumpbeam_ros.core.ident.sinusoid import ShiftPrior
from lumpbeam_ros.core.model.parameters import BeamParameters, DropTestConfig, load_beam_config
from lumpbeam_ros.core.model.simulate import simulate_drop_test
from lumpbeam_ros.core.model.statics import static_tip_deflection

RATE_HZ = 180.0
LOAD_KG = 4.5
RELEASE_S = 2.0
DURATION_S = 12.0
#: Where the identifier's fit starts after the release (fit.skip_after_release_s); the
#: peers see the same samples.
SKIP_S = IdentifierConfig().skip_after_release_s
#: Pose noise levels, m (and rad for the pitch).
LEVELS_M = (20e-6, 200e-6, 1e-3)
#: Whose drop tests: the product's lumped model and MuJoCo's chain (independent).
SOURCES = ('model', 'mujoco')
#: Trials per level: enough that an RMS ratio is known to about 15 %.
SEEDS = 20
#: The peers' frequency band: above the offset's near-zero poles, below Nyquist.
_PEER_BAND_HZ = (0.5, 0.5 * RATE_HZ)

#: ``(natural frequency Hz, damping ratio)`` of the first mode from the decay's samples.
Peer = Callable[[np.ndarray], tuple[float, float]]


def damped_sinusoid(t: np.ndarray, theta: np.ndarray) -> np.ndarray:
    """The decay model the bounds are computed for.

    ``theta = (c, A, zeta, f, p)``: ``c + A exp(-zeta w t) cos(w sqrt(1 - zeta^2) t + p)``;
    ``theta = (c, A, zeta, f, p, e, q)`` adds the amplitude-dependent level
    ``e exp(-2 zeta w t)`` and frequency (``q`` Hz at ``t = 0``, decaying as
    ``exp(-2 zeta w t)``) of :mod:`lumpbeam_ros.core.ident.sinusoid`'s nonlinear model.
    """
    c, a, zeta, f, p = theta[:5]
    w = 2.0 * math.pi * f
    rate = zeta * w
    z = c + a * np.exp(-rate * t) * np.cos(w * math.sqrt(1.0 - zeta**2) * t + p)
    if len(theta) == 7:
        e, q = theta[5:]
        square = np.exp(-2.0 * rate * t)
        # (1 - e^{-2 rate t}) / (2 rate), which tends to t as the damping vanishes.
        sweep = -np.expm1(-2.0 * rate * t) / (2.0 * rate) if rate > 0.0 else t
        phase = w * math.sqrt(1.0 - zeta**2) * t + p + 2.0 * math.pi * q * sweep
        z = c + e * square + a * np.exp(-rate * t) * np.cos(phase)
    return np.asarray(z)


def cramer_rao(
    t: np.ndarray, theta: np.ndarray, sigma: float, prior: ShiftPrior | None = None
) -> np.ndarray:
    """Standard-deviation bounds of ``theta`` for :func:`damped_sinusoid` in white noise.

    Args:
        t: Sample times from the release, s.
        theta: ``(c, A, zeta, f, p)`` or ``(c, A, zeta, f, p, e, q)``.
        sigma: Noise standard deviation, m.
        prior: With the 7 parameters: the backbone's prior on ``q``, whose information
            ``g g^T / s^2`` is added (``g`` the gradient of ``q - gamma f A^2``, ``s`` its
            standard deviation).

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
    if prior is not None:
        gamma, amplitude, f = prior.relative_per_m2, float(theta[1]), float(theta[3])
        gradient = np.array([0.0, -2.0 * gamma * f * amplitude, 0.0, -gamma * amplitude**2])
        gradient = np.concatenate([gradient, [0.0, 0.0, 1.0]])
        std = prior.relative_std * gamma * f * amplitude**2
        fisher += np.outer(gradient, gradient) / std**2
    return np.asarray(np.sqrt(np.diag(np.linalg.inv(fisher))))


def _first_mode(modes: list[tuple[float, float]]) -> tuple[float, float]:
    """The lowest in-band mode of positive damping, NaN when there is none."""
    low, high = _PEER_BAND_HZ
    found = [m for m in sorted(modes) if low <= m[0] <= high and 0.0 < m[1] < 0.5]
    return found[0] if found else (math.nan, math.nan)


def era_first_mode(z: np.ndarray) -> tuple[float, float]:
    """The first mode by pyyeti's ERA on the decay (mean removed).

    Three modes kept (the mode, the offset's remainder, a spare), selected automatically
    within the band.
    """
    from pyyeti.era import ERA

    with single_threaded_blas():
        era = ERA(
            z - np.mean(z),
            RATE_HZ,
            svd_tol=3,
            auto=True,
            verbose=False,
            show_plot=False,
            freq_range=_PEER_BAND_HZ,
        )
    modes = zip(np.atleast_1d(era.freqs_hz), np.atleast_1d(era.zeta), strict=True)
    return _first_mode([(float(f), float(zeta)) for f, zeta in modes])


def ssi_first_mode(z: np.ndarray) -> tuple[float, float]:
    """The first mode by SSI-cov on the decay.

    Order 6 (the mode, the offset's remainder, the nonlinear beam's second harmonic), 120
    block rows (two periods of the first mode).
    """
    with single_threaded_blas():
        return _first_mode(ssi_cov_modes(z, RATE_HZ, order=6, block_rows=120))


#: The peers by name, as the rows' details call them.
PEERS: dict[str, Peer] = {'era': era_first_mode, 'ssi_cov': ssi_first_mode}


def _spread(errors: np.ndarray) -> dict[str, float]:
    return {
        'rms': float(np.sqrt(np.mean(errors**2))),
        'bias': float(np.mean(errors)),
        'std': float(np.std(errors)),
        'max': float(np.max(np.abs(errors))),
    }


def _identified(
    window: PoseWindow, beam: BeamParameters, config: IdentifierConfig
) -> dict[str, float]:
    """The identifier's first mode, its standard deviations and amplitude-dependent terms."""
    result = identify(window, beam, config, strict=True).as_dict()
    keys = {
        'f': 'natural_frequency_hz',
        'f_std': 'natural_frequency_hz_std',
        'zeta': 'damping_ratio',
        'zeta_std': 'damping_ratio_std',
        'level_shift': 'amplitude_level_shift_m',
        'frequency_shift': 'amplitude_frequency_shift_hz',
    }
    return {key: float(result[name]) for key, name in keys.items()}


def _errors(
    prefix: str, found: dict[str, list[float]], truth: float, bound: float, reported: bool
) -> dict[str, float]:
    """One estimator's error figures of one parameter (``f`` or ``zeta``) in the details."""
    errors = np.asarray(found[prefix]) - truth
    spread = _spread(errors)
    details = {f'{prefix}_error_{k}': v for k, v in spread.items()}
    details[f'{prefix}_rms_over_bound'] = spread['rms'] / bound
    if reported:
        stds = np.asarray(found[f'{prefix}_std'])
        median = float(np.median(stds))
        details[f'{prefix}_reported_std_median'] = median
        details[f'{prefix}_rms_in_reported_std'] = spread['rms'] / median
        details[f'{prefix}_within_3_std'] = float(np.mean(np.abs(errors) <= 3.0 * stds))
    return details


@dataclass(frozen=True)
class DropData:
    """A noise-free drop test and the truth of its first mode."""

    t: np.ndarray
    z: np.ndarray
    pitch: np.ndarray
    natural_frequency_hz: float
    damping_ratio: float


def drop_data(beam: BeamParameters, source: str) -> DropData:
    """The drop test of ``beam``: the product's lumped model's or MuJoCo's (``mujoco``).

    MuJoCo's chain is the independent model: its own multibody dynamics and integrator
    (:func:`~lumpbeam_lab.mujoco_arm.mujoco_drop_test`); its truth is its own linearization.
    """
    if source == 'mujoco':
        drop = mujoco_drop_test(beam, LOAD_KG, RELEASE_S, DURATION_S, RATE_HZ)
        return DropData(drop.t, drop.z, drop.pitch, drop.natural_frequency_hz, drop.damping_ratio)
    exact = simulate_drop_test(beam, DropTestConfig(LOAD_KG, RELEASE_S, DURATION_S), RATE_HZ)
    truth = model_truth(beam)
    return DropData(
        exact.t, exact.z, exact.pitch, truth['natural_frequency_hz'], truth['damping_ratio']
    )


def level_row(
    sigma: float, seeds: int, peers: dict[str, Peer] | None = None, source: str = 'model'
) -> BenchResult:
    """The identifier's and the peers' frequency and damping errors at one noise level.

    Besides the identifier as configured (``fit.nonlinear`` auto, the shift held to the
    backbone) it runs the identifier with the shift free (``free_shift_``) and with
    ``fit.nonlinear`` never (``linear_``): the linear model's bias against its variance.

    Args:
        sigma: Pose noise, m.
        seeds: Trials.
        peers: The peers to run on the same trials (default :data:`PEERS`).
        source: Whose drop test: ``model`` (the product's) or ``mujoco``.

    Returns:
        The ``crb_<level>`` row (``crb_mujoco_<level>`` on MuJoCo's drop).
    """
    peers = PEERS if peers is None else peers
    beam, _ = load_beam_config()
    exact = drop_data(beam, source)
    configs = {
        '': IdentifierConfig(max_fit_s=DURATION_S),
        'free_shift_': IdentifierConfig(max_fit_s=DURATION_S, shift_prior_std=0.0),
        'linear_': IdentifierConfig(max_fit_s=DURATION_S, nonlinear='never'),
    }
    decay = exact.t >= RELEASE_S + SKIP_S
    found: dict[str, list[float]] = {}
    first: dict[str, float] = {}
    for seed in range(seeds):
        rng = np.random.default_rng(1000 + seed)
        z = exact.z + rng.normal(0.0, sigma, exact.t.size)
        pitch = exact.pitch + rng.normal(0.0, sigma, exact.t.size)
        window = clean_window(exact.t, z, pitch)
        estimates: dict[str, float] = {}
        for prefix, config in configs.items():
            for key, value in _identified(window, beam, config).items():
                estimates[prefix + key] = value
        for name, peer in peers.items():
            estimates[f'{name}_f'], estimates[f'{name}_zeta'] = peer(z[decay])
        first = first or estimates
        for key, value in estimates.items():
            found.setdefault(key, []).append(value)
    f, zeta = first['f'], first['zeta']
    # Released from rest: z = c + A0 e^{-s t} (cos w_d t + s/w_d sin w_d t) = A cos(w_d t + p).
    amplitude0 = static_tip_deflection(beam, LOAD_KG) - static_tip_deflection(beam, 0.0)
    ratio = zeta / math.sqrt(1.0 - zeta**2)
    theta = np.array([0.0, amplitude0 * math.hypot(1.0, ratio), zeta, f, -math.atan(ratio)])
    t = exact.t[exact.t >= RELEASE_S] - RELEASE_S
    bound = cramer_rao(t, theta, sigma)
    shifts = [first['level_shift'], first['frequency_shift']]
    bound_nl = cramer_rao(t, np.concatenate([theta, shifts]), sigma)
    prior = ShiftPrior(beam_backbone(beam).relative_per_m2, configs[''].shift_prior_std)
    bound_prior = cramer_rao(t, np.concatenate([theta, shifts]), sigma, prior)
    f_truth, zeta_truth = exact.natural_frequency_hz, exact.damping_ratio
    f_bound, zeta_bound = float(bound[3]), float(bound[2])
    details: dict[str, float | int] = {
        'noise_m': sigma,
        'trials': seeds,
        'f_truth_hz': f_truth,
        'f_bound': f_bound,
        'f_bound_nonlinear': float(bound_nl[3]),
        'f_bound_backbone': float(bound_prior[3]),
        'zeta_truth': zeta_truth,
        'zeta_bound': zeta_bound,
        'zeta_bound_nonlinear': float(bound_nl[2]),
        'zeta_bound_backbone': float(bound_prior[2]),
    }
    for prefix in [*configs, *(f'{name}_' for name in peers)]:
        reported = prefix in configs
        details.update(_errors(f'{prefix}f', found, f_truth, f_bound, reported))
        details.update(_errors(f'{prefix}zeta', found, zeta_truth, zeta_bound, reported))
    for bound_name in ('nonlinear', 'backbone'):
        details[f'f_rms_over_bound_{bound_name}'] = (
            details['f_error_rms'] / details[f'f_bound_{bound_name}']
        )
    return BenchResult(
        name=f'crb_{"mujoco_" if source == "mujoco" else ""}{sigma * 1e6:g}um',
        value=float(details['f_error_rms']),
        unit='Hz RMS error of f',
        baseline='Cramér-Rao bound of f (one damped sinusoid, white noise)',
        baseline_value=f_bound,
        ratio=f_bound / float(details['f_error_rms']),
        details=details,
    )


def run(quick: bool = False) -> list[BenchResult]:
    """Runs every noise level.

    Args:
        quick: Two trials per level instead of :data:`SEEDS`.

    Returns:
        One row per level, 20 um first, on the model's drop and then on MuJoCo's.
    """
    seeds = 2 if quick else SEEDS
    return [level_row(sigma, seeds, source=source) for source in SOURCES for sigma in LEVELS_M]
