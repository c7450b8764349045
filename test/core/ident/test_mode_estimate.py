"""A damped mode's figures: the paper's relations (B.20, B.21), uncertainties by Monte Carlo."""

import math

import numpy as np
import pytest

from lumpbeam_ros.core.ident.mode_estimate import ModeEstimate, damping_ratio_from_decrement

FIELDS = (
    'damped_frequency_hz',
    'natural_frequency_hz',
    'damping_ratio',
    'log_decrement',
    'decay_rate',
    'amplitude',
)


@pytest.mark.parametrize(
    ('a', 'b', 'sigma', 'omega_d'),
    [(1e-3, 0.0, 0.0455, 19.22), (-2e-4, 5e-4, 0.5, 30.0), (3e-3, -1e-3, 2.0, 6.0)],
)
def test_figures_follow_the_paper_relations(a, b, sigma, omega_d):
    mode = ModeEstimate.from_parameters(a, b, sigma, omega_d)
    # The decaying cosine itself: two damped periods apart the envelope fell by 2 delta.
    period = 2 * math.pi / omega_d
    tau = np.array([0.0, 2 * period])
    y = np.exp(-sigma * tau) * (a * np.cos(omega_d * tau) + b * np.sin(omega_d * tau))
    assert math.log(y[0] / y[1]) == pytest.approx(2 * mode.log_decrement)
    # B.21 from the decrement, and zeta = sigma / omega_n directly.
    assert damping_ratio_from_decrement(mode.log_decrement) == pytest.approx(mode.damping_ratio)
    omega_n = 2 * math.pi * mode.natural_frequency_hz
    assert mode.damping_ratio == pytest.approx(sigma / omega_n)
    # omega_d = omega_n sqrt(1 - zeta^2) (the roots of s^2 + 2 zeta omega_n s + omega_n^2).
    roots = np.roots([1.0, 2 * mode.damping_ratio * omega_n, omega_n**2])
    assert max(roots.imag) == pytest.approx(omega_d)
    assert -roots[0].real == pytest.approx(sigma)
    assert mode.amplitude == pytest.approx(math.hypot(a, b))
    assert mode.damped_omega == pytest.approx(omega_d)
    assert all(math.isnan(getattr(mode, f'{f}_std')) for f in FIELDS)


@pytest.mark.parametrize('value', [0.0, -0.1, math.nan])
def test_no_damping_ratio_without_a_positive_decrement(value):
    assert math.isnan(damping_ratio_from_decrement(value))


def test_standard_deviations_match_a_monte_carlo_propagation():
    mean = np.array([1e-3, -4e-4, 0.3, 19.0])
    root = np.diag([2e-5, 3e-5, 0.01, 0.02])
    root[2, 3] = root[3, 2] = 0.004  # sigma and omega_d correlated, as a fit leaves them
    covariance = root @ root
    mode = ModeEstimate.from_parameters(*mean, covariance)
    draws = np.random.default_rng(0).multivariate_normal(mean, covariance, size=40_000)
    samples = [ModeEstimate.from_parameters(*d) for d in draws]
    for name in FIELDS:
        spread = float(np.std([getattr(s, name) for s in samples], ddof=1))
        # First order is exact for the linear figures, within a percent or two for the rest.
        assert getattr(mode, f'{name}_std') == pytest.approx(spread, rel=0.03), name
