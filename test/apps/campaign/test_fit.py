import math

import numpy as np
import pytest

from lumpbeam_ros.apps.campaign.fit import fit_beam, slope_through_origin, weighted_mean

L, G, EI, MB, MD = 2.3107, 9.81, 4504.8, 1.9, 2.5


def _bags(loads, noise=0.0, seed=0):
    """Levels from the analytic cantilever (B.1, B.3, B.5), not from the fit's own code."""
    rng = np.random.default_rng(seed)
    loads = np.asarray(loads, float)
    sag = MB * G * L**3 / (8 * EI) + MD * G * L**3 / (3 * EI)
    deflection = loads * G * L**3 / (3 * EI) + noise * rng.standard_normal(loads.size)
    after = -sag + noise * rng.standard_normal(loads.size)
    std = np.full(loads.size, max(noise, 1e-9))
    f = np.full(loads.size, 3.0)
    return loads, deflection, std, after, std, f, np.full(loads.size, 1e-3)


def test_exact_levels_give_back_ei_and_mass():
    fit = fit_beam(*_bags([0.5, 1, 2, 5, 10]), L, G, MD)
    assert fit.bending_stiffness_nm2 == pytest.approx(EI, rel=1e-9)
    assert fit.k_total_nm_per_rad == pytest.approx(2 * EI / L, rel=1e-9)
    assert fit.beam_mass_kg == pytest.approx(MB, rel=1e-9)
    # Rayleigh's frequency of the unloaded beam with these values.
    k_v = 3 * EI / L**3
    assert fit.frequency_predicted_hz == pytest.approx(
        math.sqrt(k_v / (MD + 33 / 140 * MB)) / (2 * math.pi), rel=1e-9
    )


def test_noisy_levels_stay_within_their_uncertainty():
    pulls = []
    for seed in range(40):
        fit = fit_beam(*_bags([0.5, 1, 2, 5, 10] * 3, noise=20e-6, seed=seed), L, G, MD)
        pulls.append((fit.bending_stiffness_nm2 - EI) / fit.bending_stiffness_nm2_std)
    # The stds are honest: pulls scatter about 1 (chi-square scaling can only widen them).
    assert 0.5 < np.std(pulls) < 1.3


def test_weighted_helpers():
    mean, std, chi2 = weighted_mean(np.array([1.0, 3.0]), np.array([1.0, 1.0]))
    assert (mean, chi2) == (2.0, 2.0) and std == pytest.approx(1.0)
    s, s_std, chi2 = slope_through_origin(np.array([1.0, 2.0]), np.array([2.0, 4.0]), np.ones(2))
    assert s == pytest.approx(2.0) and chi2 == pytest.approx(0.0)


def test_needs_two_loaded_bags():
    with pytest.raises(ValueError, match='at least two'):
        fit_beam(*_bags([1.0]), L, G, MD)
