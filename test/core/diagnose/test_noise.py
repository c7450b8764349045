import numpy as np
import pytest

from lumpbeam_ros.core.diagnose.noise import decay_error_std, noise_std


@pytest.mark.parametrize('sigma', [1e-6, 20e-6, 1e-3])
def test_noise_under_a_large_swing_and_a_drop_is_recovered(sigma):
    t = np.arange(0.0, 12.0, 1.0 / 180.0)
    swing = np.where(t > 2.0, 0.04 * np.exp(-0.05 * (t - 2.0)) * np.cos(19.2 * (t - 2.0)), 0.0)
    step = np.where(t > 2.0, 0.04, 0.0)
    y = -0.07 + step + swing + sigma * np.random.default_rng(1).standard_normal(t.size)
    assert noise_std(y) == pytest.approx(sigma, rel=0.06)


def test_too_short_a_signal_reports_zero():
    assert noise_std(np.ones(6)) == 0.0


def test_the_decay_error_sees_smooth_error_that_differences_miss():
    t = np.arange(0.0, 12.0, 1.0 / 180.0)
    rng = np.random.default_rng(2)
    decay = np.where(t > 2.0, 0.04 * np.exp(-0.05 * (t - 2.0)) * np.cos(19.2 * (t - 2.0)), 0.0)
    # A slow wander, 10 um RMS, correlated over about a second: no difference sees it.
    slow = np.convolve(rng.standard_normal(t.size), np.ones(180) / 180.0, mode='same')
    y = decay + 10e-6 * slow / slow.std() + 1e-6 * rng.standard_normal(t.size)
    assert noise_std(y) < 2e-6
    assert decay_error_std(t, y, 2.3, 2.0) == pytest.approx(10e-6, rel=0.3)


def test_the_decay_error_of_too_few_samples_is_zero():
    t = np.arange(0.0, 0.05, 1.0 / 180.0)  # nine samples for seven parameters
    assert decay_error_std(t, np.sin(t), 0.0, 0.0) == 0.0
