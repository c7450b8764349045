"""Isolated outliers: one bad pose leaves the window's identification as it was."""

import numpy as np
import pytest

from lumpbeam_ros.core.bagio.tipseries import LoadSeries
from lumpbeam_ros.core.ident.identify import identify
from lumpbeam_ros.core.ident.outliers import MAX_FRACTION, spikes, without_spikes
from lumpbeam_ros.core.ident.samples import clean_window
from lumpbeam_ros.core.model.parameters import load_beam_config
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, simulate_experiment


@pytest.fixture(scope='module')
def drop():
    beam, test = load_beam_config()
    measured, _ = simulate_experiment(beam, test, SynthOptions(duration_s=10.0))
    rng = np.random.default_rng(0)
    noise = 20e-6 * rng.standard_normal((2, len(measured)))
    loads = LoadSeries(np.array([0.0, test.release_time_s]), np.array([test.load_kg, 0.0]))
    return beam, measured.t, measured.z + noise[0], measured.pitch + noise[1], loads


@pytest.mark.parametrize('spike_m', [0.002, 0.05, 0.5, 1e3, -1e3])
def test_one_outlier_pose_changes_nothing_identified(drop, spike_m):
    beam, t, z, pitch, loads = drop
    clean = identify(clean_window(t, z, pitch, loads), beam)
    bad = z.copy()
    bad[np.searchsorted(t, 6.0)] += spike_m
    result = identify(clean_window(t, bad, pitch, loads), beam)
    assert result.status == clean.status
    for key in ('natural_frequency_hz', 'damping_ratio', 'stiffness_total_nm_per_rad'):
        got, want = getattr(result.estimates, key), getattr(clean.estimates, key)
        # One pose fewer: the same estimate, well within its standard deviation.
        assert abs(got.value - want.value) < 0.1 * want.std
        assert got.std == pytest.approx(want.std, rel=0.01)
    assert result.samples.outliers == 1 and result.samples.n_rejected == 1


def test_a_clean_or_quantized_record_has_no_outliers(drop):
    _, t, z, pitch, _ = drop
    assert not spikes(z).any() and not spikes(pitch).any()
    assert not spikes(np.round(z / 1e-3) * 1e-3).any()  # 1 mm steps
    kept = (t < 6.0) | (t > 6.7)  # a gap: the samples beside it are not judged by it
    assert not spikes(z[kept], t[kept]).any() and spikes(z[kept]).any()


def test_more_outliers_than_the_limit_are_the_motion_and_stay():
    noise = 1e-3 * np.random.default_rng(2).standard_normal(1000)
    values = noise.copy()
    values[::50] += 1.0  # 2 % of the samples
    assert 0.02 > MAX_FRACTION and not spikes(values).any()
    values = noise.copy()
    values[[100, 102, 500]] = [1.0, -0.5, np.nan]  # two outliers side by side, a gap
    assert np.flatnonzero(spikes(values)).tolist() == [100, 102]


def test_a_window_without_outliers_is_returned_as_is(drop):
    _, t, z, pitch, loads = drop
    window = clean_window(t, z, pitch, loads)
    assert without_spikes(window) is window
