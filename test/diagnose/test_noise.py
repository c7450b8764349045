import numpy as np
import pytest

from lumpbeam_ros.diagnose.noise import noise_std


@pytest.mark.parametrize('sigma', [1e-6, 20e-6, 1e-3])
def test_noise_under_a_large_swing_and_a_drop_is_recovered(sigma):
    t = np.arange(0.0, 12.0, 1.0 / 180.0)
    swing = np.where(t > 2.0, 0.04 * np.exp(-0.05 * (t - 2.0)) * np.cos(19.2 * (t - 2.0)), 0.0)
    step = np.where(t > 2.0, 0.04, 0.0)
    y = -0.07 + step + swing + sigma * np.random.default_rng(1).standard_normal(t.size)
    assert noise_std(y) == pytest.approx(sigma, rel=0.06)


def test_too_short_a_signal_reports_zero():
    assert noise_std(np.ones(6)) == 0.0
