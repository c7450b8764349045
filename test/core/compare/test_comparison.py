import math

import numpy as np
import pytest

from lumpbeam_ros.core.compare.comparison import compare_sensors
from lumpbeam_ros.core.ident.identification import Status
from lumpbeam_ros.core.model.parameters import BeamParameters
from lumpbeam_ros.core.synthetic.reference_sensor import ReferenceSensorOptions

from .helpers import CAMERA_NOISE, TRACKER_NOISE, make_pair

COMBINED = math.hypot(CAMERA_NOISE, TRACKER_NOISE)

CONTRACT_KEYS = [
    'natural_frequency_hz',
    'damped_frequency_hz',
    'damping_ratio',
    'stiffness_total_nm_per_rad',
    'stiffness_vertical_n_per_m',
    'damping_total',
    'release_time_s',
    'static_deflection_m',
]


@pytest.fixture(scope='module')
def comparison(pair):
    return compare_sensors(pair.camera, pair.reference, BeamParameters(), pair.loads)


def test_difference_is_at_the_noise_level(comparison):
    # Interpolating the tracker averages neighbours, so its share is at most 15 um.
    assert 0.7 * CAMERA_NOISE < comparison.rms_difference_m < 1.5 * COMBINED
    assert comparison.max_difference_m < 6.0 * COMBINED
    assert comparison.t.size > 0.99 * 6.0 * 180


def test_both_sensors_identify_the_same_beam(comparison):
    camera, tracker = comparison.per_sensor['camera'], comparison.per_sensor['tracker']
    assert camera.status == tracker.status == Status.OK
    assert camera.estimates.natural_frequency_hz.value == pytest.approx(3.06, rel=0.01)
    assert tracker.estimates.natural_frequency_hz.value == pytest.approx(
        camera.estimates.natural_frequency_hz.value, rel=1e-4
    )
    assert tracker.estimates.damping_ratio.value == pytest.approx(
        camera.estimates.damping_ratio.value, rel=0.02
    )
    # The tracker's clock is moved onto the camera's before identifying.
    assert tracker.release.time_s.value == pytest.approx(camera.release.time_s.value, abs=2e-3)


def test_json_keys(comparison):
    result = comparison.as_dict()
    keys = ('time_offset_s', 'time_offset_s_std', 'time_offset_s_std_white')
    for key in (*keys, 'time_offset_consistency', 'rms_difference_m', 'max_difference_m'):
        assert math.isfinite(result[key])
    assert result['time_offset_s'] == pytest.approx(7.3e-3, abs=0.2e-3)
    assert set(result['per_sensor']) == {'camera', 'tracker'}
    for sensor in result['per_sensor'].values():
        for key in CONTRACT_KEYS:
            assert key in sensor
        assert sensor['status'] == 'OK'
    transform = result['transform']
    assert transform['parent_frame'] == 'beam_base' and transform['child_frame'] == 'tracker'
    assert np.allclose(transform['translation_m'], (1.2, -3.0, 0.35), atol=0.02)
    assert np.linalg.norm(transform['quaternion_xyzw']) == pytest.approx(1.0)


@pytest.mark.parametrize(
    ('tracker', 'effects', 'offset'),
    [
        # The camera late by 20 ms: its stamps run 20 ms behind the true time.
        (ReferenceSensorOptions(), {'sensor_latency': 0.02}, 7.3e-3 - 0.02),
        (ReferenceSensorOptions(clock_offset_s=0.0), {'coulomb_friction': 0.5}, 0.0),
    ],
)
def test_camera_latency_shows_as_offset(tracker, effects, offset):
    pair = make_pair(tracker, effects=effects, duration=4.0)
    comparison = compare_sensors(pair.camera, pair.reference, BeamParameters(), pair.loads)
    assert comparison.aligned.alignment.offset_s == pytest.approx(offset, abs=0.2e-3)
    assert comparison.rms_difference_m < 1.5 * COMBINED


def test_a_reflector_off_the_tip_shows_as_difference():
    pair = make_pair(ReferenceSensorOptions(lever_m=0.05), duration=4.0)
    comparison = compare_sensors(pair.camera, pair.reference, BeamParameters(), pair.loads)
    # 5 cm beyond the tip swings 5 cm x the pitch change (about 50 mrad) more than the tip.
    assert comparison.rms_difference_m > 5.0 * COMBINED
