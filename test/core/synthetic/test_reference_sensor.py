from dataclasses import replace

import numpy as np
import pytest

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.bagio import open_bag, read_points, read_tip_poses
from lumpbeam_ros.core.model.parameters import BeamParameters, DropTestConfig
from lumpbeam_ros.core.model.simulate import simulate_loads
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, write_drop_test_bag
from lumpbeam_ros.core.synthetic.reference_sensor import (
    ReferenceSensorOptions,
    simulate_reference_sensor,
)

DROP = DropTestConfig()


@pytest.mark.parametrize('offset', [7.3e-3, -0.05])
def test_stamps_are_true_time_plus_offset(offset):
    options = ReferenceSensorOptions(clock_offset_s=offset, noise_m=0.0)
    samples = simulate_reference_sensor(BeamParameters(), DROP, 3.0, options)
    assert samples.stamps[0] >= 0.0
    assert np.allclose(np.diff(samples.stamps), 1e-3)
    true_t = samples.stamps - offset
    tip = simulate_loads(BeamParameters(), true_t, [(2.0, 0.0)], 4.5)
    back = options.transform.apply(samples.points)
    assert np.max(np.abs(back[:, 2] - tip.z)) < 1e-12
    assert np.max(np.abs(back[:, 1])) < 1e-12


def test_noise_and_frame():
    options = ReferenceSensorOptions()
    samples = simulate_reference_sensor(BeamParameters(), DROP, 3.0, options)
    in_tracker = options.transform.inverse().apply(samples.true_points)
    assert np.std(samples.points - in_tracker) == pytest.approx(15e-6, rel=0.05)
    # The tracker stands 3.2 m from the tip, below its level.
    tip_from_tracker = np.array([2.31, 0.0, -0.05]) - np.array(options.position_m)
    distance = np.linalg.norm(tip_from_tracker)
    assert np.linalg.norm(samples.points, axis=1).mean() == pytest.approx(distance, abs=0.01)


def test_latency_is_the_camera_s_not_the_tracker_s():
    late = BeamParameters().effects.with_effect('sensor_latency', 0.02)
    beam = BeamParameters()
    a = simulate_reference_sensor(
        replace(beam, effects=late), DROP, 3.0, ReferenceSensorOptions(noise_m=0.0)
    )
    b = simulate_reference_sensor(beam, DROP, 3.0, ReferenceSensorOptions(noise_m=0.0))
    assert np.array_equal(a.points, b.points)


def test_lever_moves_the_reflector_along_the_tangent():
    plain = simulate_reference_sensor(
        BeamParameters(), DROP, 3.0, ReferenceSensorOptions(noise_m=0.0)
    )
    lever = simulate_reference_sensor(
        BeamParameters(), DROP, 3.0, ReferenceSensorOptions(noise_m=0.0, lever_m=0.1)
    )
    step = lever.true_points - plain.true_points
    assert np.allclose(np.linalg.norm(step, axis=1), 0.1)
    loaded = plain.stamps - 7.3e-3 < DROP.release_time_s
    assert np.all(step[loaded, 2] < -1e-3)  # the tip points down under load


def test_bag_holds_the_points_in_time_order(tmp_path):
    options = SynthOptions(duration_s=3.0)
    write_drop_test_bag(
        tmp_path / 'bag', BeamParameters(), DROP, options, tracker=ReferenceSensorOptions()
    )
    points = read_points(tmp_path / 'bag')
    assert points.frame_id == 'tracker'
    assert points.t.size == 3001
    assert points.t[0] == pytest.approx(7.3e-3)
    assert read_tip_poses(tmp_path / 'bag').t.size == 3 * 180 + 1
    log_times = [m.log_time_ns for m in open_bag(tmp_path / 'bag').iter_raw()]
    assert log_times == sorted(log_times)


def test_synth_cli_tracker_options(tmp_path, capsys):
    argv = ['synth', str(tmp_path / 'bag'), '--duration', '2.5', '--tracker']
    argv += ['--tracker-rate', '500', '--tracker-pose', '0,2,0,0,0,90', '--tracker-offset', '0']
    assert main(argv) == 0
    assert '/tracker/point at 500 Hz' in capsys.readouterr().out
    points = read_points(tmp_path / 'bag')
    poses = read_tip_poses(tmp_path / 'bag')
    assert points.t.size == 1251
    # Yawed 90 deg about z: the beam's x axis is the tracker's -y axis.
    assert np.median(-points.y) == pytest.approx(np.median(poses.x), abs=1e-3)


@pytest.mark.parametrize(
    'argv',
    [
        ['--tracker-pose', '1,2,3'],
        ['--tracker-pose', '1,2,3,a,b,c'],
        ['--tracker-rate', '0'],
        ['--tracker-noise', '-1'],
    ],
)
def test_synth_cli_rejects_bad_tracker_options(tmp_path, capsys, argv):
    with pytest.raises(SystemExit) as exc:
        main(['synth', str(tmp_path / 'bag'), '--tracker', *argv])
    assert exc.value.code == 2
    assert 'error' in capsys.readouterr().err


@pytest.mark.parametrize(
    'kwargs',
    [{'rate_hz': 0.0}, {'noise_m': -1e-6}, {'clock_offset_s': float('nan')}, {'frame_id': ''}],
)
def test_bad_tracker_options(kwargs):
    with pytest.raises(LumpbeamError):
        ReferenceSensorOptions(**kwargs)
