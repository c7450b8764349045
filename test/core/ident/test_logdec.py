import math

import numpy as np
import pytest

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.logdec import LogDecrement, difference_noise_std
from lumpbeam_ros.core.ident.mode_estimate import damping_ratio_from_decrement

T = np.arange(0.0, 10.0, 1.0 / 180.0)


def _decay(zeta, f_d=3.0):
    w = 2 * math.pi * f_d
    sigma = zeta * w / math.sqrt(1 - zeta**2)
    return 0.02 * np.exp(-sigma * T) * np.cos(w * T)


@pytest.mark.parametrize('zeta', [0.002, 0.02, 0.05])
def test_decrement_and_b21_on_a_clean_decay(zeta):
    result = LogDecrement().fit(T, _decay(zeta), offset=0.0, noise_std=1e-6)
    expected = 2 * math.pi * zeta / math.sqrt(1 - zeta**2)  # sigma T_d
    assert result.log_decrement == pytest.approx(expected, rel=5e-3)
    assert result.damping_ratio == pytest.approx(zeta, rel=5e-3)
    assert result.damped_frequency_hz == pytest.approx(3.0, rel=1e-4)
    assert result.periods == result.peak_times.size - 1 or result.periods >= 2


def test_b21_formula():
    assert damping_ratio_from_decrement(2 * math.pi) == pytest.approx(1 / math.sqrt(2))
    assert math.isnan(damping_ratio_from_decrement(0.0))


def test_noisy_decay_std_covers_the_error():
    rng = np.random.default_rng(4)
    zeta = 0.01
    y = _decay(zeta) + rng.normal(0, 20e-6, T.size)
    result = LogDecrement().fit(T, y, offset=0.0)
    assert result.noise_std == pytest.approx(20e-6, rel=0.15)
    assert abs(result.damping_ratio - zeta) < 4 * result.damping_ratio_std
    envelope = LogDecrement().fit(T, y, offset=0.0)
    assert envelope.envelope(np.array([envelope.peak_times[0]]))[0] == pytest.approx(
        envelope.peak_amplitudes[0]
    )


def test_no_oscillation_raises():
    rng = np.random.default_rng(5)
    with pytest.raises(LumpbeamError, match='no oscillation|fewer than two peaks'):
        LogDecrement().fit(T, rng.normal(0, 1e-6, T.size), noise_std=1e-5)
    with pytest.raises(LumpbeamError, match='before fit'):
        LogDecrement().predict(T)


def test_difference_noise_ignores_a_slow_oscillation():
    rng = np.random.default_rng(6)
    y = 0.04 * np.cos(2 * math.pi * 3 * T) + rng.normal(0, 20e-6, T.size)
    assert difference_noise_std(y) == pytest.approx(20e-6, rel=0.5)
