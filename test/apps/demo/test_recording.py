import numpy as np
import pytest

from lumpbeam_ros.apps.demo.recording import (
    analyze_recording,
    clock_time,
    last_live_status,
    normalize_recording,
)
from lumpbeam_ros.base.errors import BagError
from lumpbeam_ros.core.bagio import BagWriter, convert, read_load_events
from lumpbeam_ros.core.model.parameters import BeamParameters, DropTestConfig
from lumpbeam_ros.core.model.simulate import simulate_drop_test

WALL = 1_700_000_000.0  # the recorder logs in wall time; the poses carry sim time
BEAM = BeamParameters()


def _write_recording(path, with_clock=True, predicted_offset=0.0, noise=20e-6):
    """A bag as the demo's recorder writes it: sim-time stamps, wall-time log times."""
    truth = simulate_drop_test(BEAM, DropTestConfig(duration_s=6.0))
    rng = np.random.default_rng(3)
    with BagWriter(path) as bag:
        for i, t in enumerate(truth.t):
            ns = convert.seconds_to_ns(t)
            wall = convert.seconds_to_ns(WALL + t + 0.002)
            if with_clock:
                bag.write_message('/clock', convert.clock(ns), wall)
            z = truth.z[i] + noise * rng.standard_normal()
            pose = convert.pose_stamped(ns, truth.x[i], z, truth.pitch[i], 'beam_base')
            bag.write_message('/tip_pose', pose, wall + 1000)
            pred = convert.pose_stamped(
                ns, truth.x[i], truth.z[i] + predicted_offset, truth.pitch[i], 'beam_base'
            )
            bag.write_message('/tip_pose_predicted', pred, wall + 2000)
            if i % 180 == 0 or t == 2.0:
                kg = 4.5 if t < 2.0 else 0.0
                bag.write_message('/tip_load', convert.float64(kg), wall + 3000)
        status = convert.Status('lumpbeam/identifier', 0, 'ok', {'natural_frequency_hz': '3.06'})
        # Stamped at sim time, logged (received) at wall time, as the recorder does.
        array = convert.diagnostic_array(convert.seconds_to_ns(5.0), [status], '')
        bag.write_message('/beam_params', array, convert.seconds_to_ns(WALL + 6.0))
    return path


def test_clock_time_takes_the_latest_clock_before():
    log = np.array([10.0, 11.0, 12.0])
    value = np.array([0.0, 1.0, 2.0])
    got = clock_time(np.array([9.0, 10.0, 10.5, 11.0, 99.0]), log, value)
    np.testing.assert_array_equal(got, [np.nan, 0.0, 0.0, 1.0, 2.0])


def test_normalized_recording_is_identified_and_matches_the_prediction(tmp_path):
    recorded = _write_recording(tmp_path / 'recorded')
    normalized = normalize_recording(recorded, tmp_path / 'sim')
    loads = read_load_events(normalized)
    assert loads.t[0] == 0.0 and 2.0 in loads.t  # in sim time now, not wall time
    analysis = analyze_recording(normalized, BEAM)
    ident = analysis.identification
    assert ident.ok and ident.release.time_s.value == pytest.approx(2.0, abs=0.01)
    assert ident.estimates.natural_frequency_hz.value == pytest.approx(3.0588, rel=1e-3)
    assert analysis.residual.rms() == pytest.approx(20e-6, rel=0.15)  # only the noise
    assert analysis.live == {'natural_frequency_hz': '3.06'} and analysis.live_level == 0
    assert last_live_status(recorded)[0] == analysis.live


def test_an_offset_prediction_shows_in_the_residual(tmp_path):
    recorded = _write_recording(tmp_path / 'recorded', predicted_offset=1e-3, noise=0.0)
    analysis = analyze_recording(normalize_recording(recorded, tmp_path / 'sim'), BEAM)
    np.testing.assert_allclose(analysis.residual.residual, -1e-3, atol=1e-9)


def test_a_recording_without_clock_is_refused(tmp_path):
    recorded = _write_recording(tmp_path / 'recorded', with_clock=False)
    with pytest.raises(BagError, match='/clock'):
        normalize_recording(recorded, tmp_path / 'sim')


def test_missing_prediction_is_a_bag_error(tmp_path):
    with BagWriter(tmp_path / 'only_pose') as bag:
        bag.write_pose('/tip_pose', 0.0, 2.3, -0.05, 0.0)
        bag.write_float('/tip_load', 0.0, 4.5)
    with pytest.raises(BagError, match='tip_pose_predicted'):
        analyze_recording(tmp_path / 'only_pose', BEAM)


def test_live_values_keep_the_latest_estimate_of_each_key(tmp_path):
    # Near the end of a record the window loses the release: the stiffness turns NaN while
    # the frequency stays current. The summary keeps the last stiffness it had.
    bag = tmp_path / 'live'
    with BagWriter(bag) as writer:
        for stamp, k, f, level in ((1.0, '3885.0', '3.05', 0), (2.0, 'nan', '3.06', 1)):
            status = convert.Status(
                'lumpbeam/identifier',
                level,
                'test',
                {'stiffness_total_nm_per_rad': k, 'natural_frequency_hz': f},
            )
            writer.write_diagnostics('/beam_params', stamp, [status])
    values, level = last_live_status(bag)
    assert values == {'stiffness_total_nm_per_rad': '3885.0', 'natural_frequency_hz': '3.06'}
    assert level == 1


def test_the_normalized_recording_is_in_log_time_order(tmp_path, mcap_doctor):
    # Each topic's messages come in their own order (the poses stamped at sim time, the
    # parameters at their own); the copy used to be written topic by topic, which the mcap
    # doctor flagged as "log_time out of order".
    normalized = normalize_recording(_write_recording(tmp_path / 'rec'), tmp_path / 'sim')
    log_times = [ns for ns, _ in _file_order(normalized)]
    assert log_times == sorted(log_times) and len(log_times) > 2000
    assert mcap_doctor(normalized) == ''


def _file_order(bag):
    from mcap.reader import make_reader

    with next(bag.glob('*.mcap')).open('rb') as stream:
        reader = make_reader(stream)
        return [(m.log_time, c.topic) for _, c, m in reader.iter_messages(log_time_order=False)]
