import math
import warnings
from dataclasses import replace

import numpy as np
import pytest

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.sinusoid import DampedSinusoidFit, ShiftPrior, spectral_peak_hz

T = np.arange(0.0, 8.0, 1.0 / 180.0)
F_D, ZETA, OFFSET, AMP = 3.1, 0.01, -0.01, 0.02


def _decay(t, f_d=F_D, zeta=ZETA, amp=AMP, phase=0.3):
    w = 2 * math.pi * f_d
    sigma = zeta * w / math.sqrt(1 - zeta**2)
    return amp * np.exp(-sigma * t) * np.cos(w * t + phase)


def _ar1(rng, n, phi, std):
    """AR(1) noise of marginal std ``std``: what a smoothing tracker leaves."""
    e = rng.normal(0.0, std * math.sqrt(1 - phi**2), n + 200)
    out = np.empty_like(e)
    out[0] = e[0]
    for i in range(1, e.size):
        out[i] = phi * out[i - 1] + e[i]
    return out[200:]


def test_fit_recovers_a_clean_decay_and_predicts_it():
    y = OFFSET + _decay(T)
    fit = DampedSinusoidFit()
    params = fit.fit(T, y)
    mode = params.mode(0)
    assert mode.damped_frequency_hz == pytest.approx(F_D, rel=1e-9)
    assert mode.damping_ratio == pytest.approx(ZETA, rel=1e-7)
    assert params.offset == pytest.approx(OFFSET, abs=1e-12)
    assert mode.amplitude == pytest.approx(AMP, rel=1e-8)
    np.testing.assert_allclose(fit.predict(T), y, atol=1e-12)


def test_drift_and_second_mode_are_fitted():
    y = OFFSET + 1e-4 * T + _decay(T) + _decay(T, f_d=21.0, zeta=0.02, amp=5e-4)
    params = DampedSinusoidFit(n_modes=2, drift=True).fit(T, y)
    assert params.drift_rate == pytest.approx(1e-4, rel=1e-6)
    assert params.mode(1).damped_frequency_hz == pytest.approx(21.0, rel=1e-6)
    assert params.mode(0).damping_ratio == pytest.approx(ZETA, rel=1e-6)


@pytest.mark.parametrize(('phi', 'noise'), [(0.0, 50e-6), (0.9, 50e-6)], ids=['white', 'ar1'])
def test_reported_std_matches_the_scatter(phi, noise):
    # Monte Carlo: the spread of 80 fits must match the std each fit reports, also when the
    # noise is correlated, where the white-noise formula would be ~4x too small.
    rng = np.random.default_rng(11)
    freqs, zetas, f_std, z_std, white = [], [], [], [], []
    for _ in range(80):
        y = OFFSET + _decay(T) + _ar1(rng, T.size, phi, noise)
        params = DampedSinusoidFit().fit(T, y)
        mode = params.mode(0)
        freqs.append(mode.damped_frequency_hz)
        zetas.append(mode.damping_ratio)
        f_std.append(mode.damped_frequency_hz_std)
        z_std.append(mode.damping_ratio_std)
        white.append(math.sqrt(params.covariance.white[4, 4]) / (2 * math.pi))
    for values, stds in ((freqs, f_std), (zetas, z_std)):
        ratio = np.std(values) / np.mean(stds)
        assert 0.75 < ratio < 1.33, ratio
    white_ratio = np.std(freqs) / np.mean(white)
    assert (white_ratio > 2.0) if phi else (0.75 < white_ratio < 1.33)


def test_predict_before_fit_and_too_few_samples_raise():
    with pytest.raises(LumpbeamError, match='before fit'):
        DampedSinusoidFit().predict(T)
    with pytest.raises(LumpbeamError, match='7 samples for 5 parameters'):
        DampedSinusoidFit().fit(T[:7], T[:7])
    with pytest.raises(ValueError):
        DampedSinusoidFit(n_modes=0)


def test_spectral_peak_on_uneven_stamps():
    t = np.sort(np.random.default_rng(1).uniform(0, 10, 1500))
    assert spectral_peak_hz(t, np.sin(2 * math.pi * 4.2 * t), 1.0, 20.0) == pytest.approx(
        4.2, rel=2e-3
    )
    assert math.isnan(spectral_peak_hz(t, np.sin(t), 500.0, 600.0))


def _weakly_nonlinear(t, q_hz=2e-3, e=3e-5, f_d=F_D, zeta=ZETA, amp=AMP):
    """A decay whose frequency and centre shift with the squared amplitude."""
    w = 2 * math.pi * f_d
    sigma = zeta * w / math.sqrt(1 - zeta**2)
    square = np.exp(-2 * sigma * t)
    phase = w * t + 2 * math.pi * q_hz * (1 - square) / (2 * sigma)
    return OFFSET + e * square + amp * np.exp(-sigma * t) * np.cos(phase + 0.3)


def test_nonlinear_terms_remove_the_amplitude_bias():
    y = _weakly_nonlinear(T)
    linear = DampedSinusoidFit().fit(T, y).mode(0)
    params = DampedSinusoidFit(nonlinear=True).fit(T, y)
    # The linear fit runs at a frequency averaged over the decay, off by ~q/2.
    assert abs(linear.damped_frequency_hz - F_D) > 5e-4
    assert params.mode(0).damped_frequency_hz == pytest.approx(F_D, rel=1e-9)
    assert params.frequency_shift_hz == pytest.approx(2e-3, rel=1e-6)
    assert params.level_shift_m == pytest.approx(3e-5, rel=1e-6)
    assert params.offset == pytest.approx(OFFSET, abs=1e-12)
    assert DampedSinusoidFit().fit(T, y).frequency_shift_hz == 0.0


#: The backbone that gives :func:`_weakly_nonlinear` its shift: q = gamma f A^2, 1/m^2.
GAMMA = 2e-3 / (F_D * AMP**2)


def test_a_shift_prior_gives_back_the_frequency_precision_the_free_shift_costs():
    rng = np.random.default_rng(4)
    y = _weakly_nonlinear(T) + rng.normal(0.0, 200e-6, T.size)
    free = DampedSinusoidFit(nonlinear=True).fit(T, y)
    held = DampedSinusoidFit(nonlinear=True, shift_prior=ShiftPrior(GAMMA, 0.1)).fit(T, y)
    assert held.shift_prior == ShiftPrior(GAMMA, 0.1)
    assert free.shift_prior is None
    f_free, f_held = free.mode(0), held.mode(0)
    assert f_held.damped_frequency_hz_std < f_free.damped_frequency_hz_std / 1.5
    for mode in (f_free, f_held):
        assert abs(mode.damped_frequency_hz - F_D) < 3.0 * mode.damped_frequency_hz_std
    assert held.frequency_shift_hz == pytest.approx(2e-3, rel=0.3)


def test_noise_free_data_overrule_a_wrong_prior():
    # The prior is weighed against the residual noise: with none, the data alone decide.
    y = _weakly_nonlinear(T)
    params = DampedSinusoidFit(nonlinear=True, shift_prior=ShiftPrior(-GAMMA, 0.01)).fit(T, y)
    assert params.frequency_shift_hz == pytest.approx(2e-3, rel=1e-6)
    assert params.mode(0).damped_frequency_hz == pytest.approx(F_D, rel=1e-9)


def test_a_refit_keeps_the_model_and_the_prior():
    rng = np.random.default_rng(5)
    y = _weakly_nonlinear(T) + rng.normal(0.0, 200e-6, T.size)
    cold = DampedSinusoidFit(nonlinear=True, shift_prior=ShiftPrior(GAMMA, 0.1)).fit(T, y)
    again = DampedSinusoidFit.like(cold)
    assert (again.nonlinear, again.shift_prior, again.n_modes) == (True, cold.shift_prior, 1)
    warm = again.fit(T, y, start=cold)
    assert warm.mode(0).damped_frequency_hz == pytest.approx(
        cold.mode(0).damped_frequency_hz, abs=0.01 * cold.mode(0).damped_frequency_hz_std
    )
    # A linear fit has no shift to hold: the prior is kept for a later nonlinear refit only.
    linear = DampedSinusoidFit(shift_prior=ShiftPrior(GAMMA, 0.1)).fit(T, y)
    assert linear.shift_prior is None and linear.frequency_shift_hz == 0.0


@pytest.mark.parametrize('nonlinear', [False, True])
def test_shifted_origin_describes_the_same_curve(nonlinear):
    y = _weakly_nonlinear(T) + 1e-4 * T
    params = DampedSinusoidFit(n_modes=2, drift=True, nonlinear=nonlinear).fit(
        T, y, initial=[(F_D, ZETA), (21.0, 0.02)]
    )
    for t0 in (2.5, -1.0):
        moved = params.shifted(t0)
        assert moved.t0 == t0
        np.testing.assert_allclose(moved.predict(T), params.predict(T), atol=1e-14)
        assert moved.mode(0).damped_frequency_hz == params.mode(0).damped_frequency_hz
    assert params.shifted(params.t0) is params


def test_warm_start_converges_quickly_to_the_cold_solution():
    rng = np.random.default_rng(5)
    y = _weakly_nonlinear(T) + rng.normal(0.0, 20e-6, T.size)
    first = DampedSinusoidFit(nonlinear=True).fit(T[:-9], y[:-9])
    cold = DampedSinusoidFit(nonlinear=True).fit(T[9:], y[9:])
    warm = DampedSinusoidFit(nonlinear=True).fit(T[9:], y[9:], start=first)
    np.testing.assert_allclose(warm.x, cold.x, rtol=1e-6, atol=1e-12)
    assert warm.n_evaluations < cold.n_evaluations
    # A linear start serves a nonlinear fit (and the reverse); other modes do not.
    linear = DampedSinusoidFit().fit(T, y)
    assert DampedSinusoidFit(nonlinear=True).fit(T, y, start=linear).nonlinear
    assert not DampedSinusoidFit().fit(T, y, start=warm).nonlinear
    with pytest.raises(LumpbeamError, match='other modes'):
        DampedSinusoidFit(n_modes=2).fit(T, y, start=linear)


#: A live identifier's last solution, 0.094 s before the window it starts (the synthetic drop
#: test replayed without /tip_load): its second mode is a fast decay with no amplitude left.
_LIVE_START_X = [-0.028921, 0.0099800, -0.039365, 0.045495, 19.217572, -0.049506, -0.050303,
                 31.891904, 23.498564, -2.7660e-05, 0.0020493]  # fmt: skip


def test_trial_steps_that_overflow_are_rejected_without_numpy_warnings():
    rng = np.random.default_rng(0)
    tau = np.arange(1801) / 180.0
    envelope = np.exp(-0.0455 * tau)
    y = -0.0289 + envelope * (-0.0404 * np.cos(19.2187 * tau) - 1e-4 * np.sin(19.2187 * tau))
    y += rng.normal(0.0, 20e-6, tau.size)
    fit = DampedSinusoidFit(n_modes=2, nonlinear=True, min_frequency_hz=0.05)
    first = fit.fit(tau, y)
    start = replace(first, t0=-0.094444444, x=np.array(_LIVE_START_X))
    with warnings.catch_warnings():
        warnings.simplefilter('error')  # the solver's far trial steps once printed two
        params = fit.fit(tau, y, start=start)
    assert np.all(np.isfinite(params.x))
    assert params.x[4] == pytest.approx(19.2187, rel=1e-4)
