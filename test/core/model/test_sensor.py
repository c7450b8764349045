from dataclasses import replace

import numpy as np
import pytest

from lumpbeam_ros.core.model.parameters import BeamParameters, Effects
from lumpbeam_ros.core.model.sensor import measured_position, rest_position, scaled_position
from lumpbeam_ros.core.model.simulate import simulate_loads
from lumpbeam_ros.core.model.statics import static_tip_deflection

BEAM = BeamParameters()
EVENTS = [(1.0, 0.0)]


@pytest.mark.parametrize('scale', [0.9, 1.0, 1.07])
def test_the_measured_displacement_from_rest_is_scale_times_the_true_one(scale):
    t = np.arange(0.0, 3.0, 1 / 180)
    true = simulate_loads(BEAM, t, EVENTS, 4.5)
    scaled = replace(BEAM, effects=Effects().with_effect('sensor_scale', scale))
    seen = simulate_loads(scaled, t, EVENTS, 4.5)
    x0, z0 = rest_position(BEAM)
    np.testing.assert_allclose(seen.z - z0, scale * (true.z - z0), rtol=0, atol=1e-12)
    np.testing.assert_allclose(seen.x - x0, scale * (true.x - x0), rtol=0, atol=1e-12)
    np.testing.assert_array_equal(seen.pitch, true.pitch)  # a depth error leaves angles alone
    # The static level: the loaded rest sits scale times the load's static sag below rest.
    sag = static_tip_deflection(BEAM, 4.5) - static_tip_deflection(BEAM)
    assert z0 - seen.z[0] == pytest.approx(scale * sag, rel=1e-9)


def test_scale_one_is_off_and_is_stored_as_zero():
    effects = Effects().with_effect('sensor_scale', 1.0)
    assert effects == Effects() and effects.active() == {}
    assert Effects().value('sensor_scale') == 1.0
    x = np.array([1.0, 2.0])
    assert scaled_position(BEAM, x, x) == (x, x)


@pytest.mark.parametrize('rate', [-2e-4, 5e-5])
def test_a_creeping_mount_moves_only_the_measured_z_by_rate_times_elapsed_time(rate):
    # A clamp moving at constant velocity is an inertial frame: the beam's motion relative
    # to it is that of a still clamp (Galileo), so the angles are unchanged and the measured
    # z, taken against the fixed board, moves by the distance crept since the start.
    t = np.arange(0.5, 3.0, 1 / 180)
    still = simulate_loads(BEAM, t, EVENTS, 4.5)
    crept = simulate_loads(
        replace(BEAM, effects=Effects().with_effect('mount_creep', rate)), t, EVENTS, 4.5
    )
    np.testing.assert_allclose(crept.z - still.z, rate * (t - t[0]), rtol=0, atol=1e-15)
    np.testing.assert_array_equal(crept.x, still.x)
    np.testing.assert_array_equal(crept.pitch, still.pitch)
    np.testing.assert_array_equal(crept.q, still.q)
    x = np.array([2.3, 2.3])
    assert measured_position(BEAM, np.array([0.0, 1.0]), x, x) == (x, x)  # off: untouched
