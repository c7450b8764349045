import numpy as np
import pytest
from scipy.signal import find_peaks

from lumpbeam_ros.core.ident.peaks import lobe_peaks, vertices

T = np.arange(0.0, 4.0, 1.0 / 180.0)
F_HZ, SIGMA, PHASE = 3.05, 0.4, -np.pi / 2  # starts at the level: no lobe cut by t = 0


def _decay(noise=0.0, seed=0):
    s = 0.02 * np.exp(-SIGMA * T) * np.cos(2.0 * np.pi * F_HZ * T + PHASE)
    return s + noise * np.random.default_rng(seed).standard_normal(T.size)


@pytest.mark.parametrize('signs', ['positive', 'both'])
def test_the_lobes_are_scipys_peaks_on_a_clean_decay(signs):
    s = _decay()
    found = lobe_peaks(s, 1e-4, signs)
    assert found[-1] == T.size - 1  # the lobe the record's end cuts: its last sample
    found = found[:-1]
    expected = find_peaks(s)[0]  # an independent finder: local maxima
    if signs == 'both':
        expected = np.sort(np.r_[expected, find_peaks(-s)[0]])
    expected = expected[np.abs(s[expected]) > 1e-4]
    np.testing.assert_array_equal(found, expected)


def test_noise_inside_the_band_does_not_split_a_lobe():
    s = _decay(noise=2e-4, seed=1)
    peaks = lobe_peaks(s, 4 * 2e-4, 'both')
    assert np.all(np.diff(np.sign(s[peaks])) != 0)  # the signs alternate: one peak a lobe
    assert peaks.size == lobe_peaks(_decay(), 4 * 2e-4, 'both').size  # as without noise
    assert len(find_peaks(s)[0]) + len(find_peaks(-s)[0]) > 2 * peaks.size  # noise extrema


def test_the_vertices_are_the_true_peaks_between_samples():
    s = _decay()
    times, heights = vertices(T, s, lobe_peaks(s, 1e-4, 'both')[:-1])
    # The decaying cosine's extrema: where its derivative vanishes, in closed form.
    omega = 2.0 * np.pi * F_HZ
    phase = -np.arctan(SIGMA / omega)
    k = np.round((omega * times + PHASE - phase) / np.pi)
    exact = (k * np.pi + phase - PHASE) / omega
    np.testing.assert_allclose(times, exact, atol=2e-4)  # 1/30 of a sample
    truth = 0.02 * np.exp(-SIGMA * exact) * np.cos(omega * exact + PHASE)
    np.testing.assert_allclose(heights, truth, rtol=3e-3)
    assert np.all(np.sign(heights[::2]) == np.sign(heights[0]))


def test_no_sample_outside_the_band_gives_no_peak():
    assert lobe_peaks(np.zeros(10), 0.1).size == 0
