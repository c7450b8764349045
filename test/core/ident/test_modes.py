import math

import numpy as np
import pytest

from lumpbeam_ros.core.ident.modes import (
    choose_modes,
    detection_threshold,
    harmonic_of,
    mode_significance,
    structural_modes,
)
from lumpbeam_ros.core.ident.settings import IdentifierConfig
from lumpbeam_ros.core.ident.sinusoid import DampedSinusoidFit

RATE_HZ = 180.0
NOISE_M = 20e-6


def _decay(modes, seconds=8.0, seed=0):
    """Offset plus damped cosines ``(f_n Hz, zeta, amplitude m)`` with white noise."""
    t = np.arange(int(seconds * RATE_HZ)) / RATE_HZ
    z = np.full(t.size, -0.03)
    for f, zeta, amplitude in modes:
        omega = 2 * math.pi * f
        z += amplitude * np.exp(-zeta * omega * t) * np.cos(omega * math.sqrt(1 - zeta**2) * t)
    return t, z + np.random.default_rng(seed).normal(0.0, NOISE_M, t.size)


def _choose(t, z, config=None):
    first = DampedSinusoidFit(n_modes=1).fit(t, z, initial=[(3.0, 0.005)])
    return choose_modes(t, z, first, config or IdentifierConfig())


def _frequencies(params):
    return sorted(params.mode(m).natural_frequency_hz for m in structural_modes(params))


def test_two_known_modes_are_recovered_within_their_standard_deviations():
    truth = [(3.0, 0.005, 0.02), (19.0, 0.02, 4e-4)]
    t, z = _decay(truth)
    choice = _choose(t, z)
    params = choice.params
    assert params.n_modes == 2, choice.refused
    modes = sorted((params.mode(m) for m in range(2)), key=lambda m: m.natural_frequency_hz)
    for mode, (f, zeta, amplitude) in zip(modes, truth, strict=True):
        assert abs(mode.natural_frequency_hz - f) < 4 * mode.natural_frequency_hz_std
        assert abs(mode.damping_ratio - zeta) < 4 * mode.damping_ratio_std
        assert mode.amplitude == pytest.approx(amplitude, rel=0.1)
    assert mode_significance(params, 1) > choice.threshold
    # The third search found nothing that stands out of the noise.
    assert 'below the noise threshold' in choice.refused or 'no further mode' in choice.refused


def test_a_mode_buried_in_the_noise_is_refused():
    # 10 um at 19 Hz, gone in about 0.4 s: about 3 sigma of its own amplitude, under the 5 sigma
    # that 1440 samples ask for.
    t, z = _decay([(3.0, 0.005, 0.02), (19.0, 0.02, 1e-5)])
    choice = _choose(t, z)
    assert _frequencies(choice.params) == pytest.approx([3.0], rel=1e-3)
    assert 'below the noise threshold' in choice.refused or 'no further mode' in choice.refused


def test_max_modes_one_never_searches():
    t, z = _decay([(3.0, 0.005, 0.02), (19.0, 0.02, 4e-4)])
    choice = _choose(t, z, IdentifierConfig(max_modes=1))
    assert choice.params.n_modes == 1 and choice.refused == ''


def test_the_threshold_is_the_bonferroni_level_of_the_noise_alone():
    k = detection_threshold(1800, 1e-3)
    assert k == pytest.approx(math.sqrt(2 * math.log(1.8e6)))
    # A 2-dof chi-square exceeds k^2 with probability exp(-k^2 / 2): alpha / N.
    assert math.exp(-(k**2) / 2) == pytest.approx(1e-3 / 1800)


def test_noise_alone_gives_no_second_mode():
    spurious = 0
    for seed in range(4):
        t, z = _decay([(3.0, 0.005, 0.02)], seconds=6.0, seed=seed)
        spurious += _choose(t, z).params.n_modes - 1
    assert spurious == 0


def test_a_harmonic_of_a_large_swing_is_fitted_but_is_not_a_mode():
    t, z = _decay([(3.0, 0.005, 0.02)])
    # The third harmonic of the swing: three times the frequency, three times the decay.
    omega, sigma = 2 * math.pi * 3.0 * math.sqrt(1 - 0.005**2), 0.005 * 2 * math.pi * 3.0
    z = z + 3e-4 * np.exp(-3 * sigma * t) * np.cos(3 * omega * t)
    params = _choose(t, z).params
    assert params.n_modes == 2
    third = max(range(2), key=lambda m: params.mode(m).natural_frequency_hz)
    assert harmonic_of(params, third) == 1 - third
    assert _frequencies(params) == pytest.approx([3.0], rel=1e-3)
