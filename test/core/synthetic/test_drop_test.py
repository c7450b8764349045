import math

import numpy as np
import pytest

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.bagio import read_load_events, read_tip_poses
from lumpbeam_ros.core.model.parameters import BeamParameters, DropTestConfig
from lumpbeam_ros.core.model.simulate import simulate_loads
from lumpbeam_ros.core.synthetic.drop_test import (
    MAX_SAMPLES,
    SynthOptions,
    check_sample_count,
    parse_effect,
    simulate_experiment,
    with_effects,
    write_drop_test_bag,
)


def test_bag_holds_noisy_poses_truth_and_loads(tmp_path):
    options = SynthOptions(duration_s=4.0, seed=3)
    write_drop_test_bag(tmp_path / 'bag', BeamParameters(), DropTestConfig(), options)
    measured = read_tip_poses(tmp_path / 'bag')
    truth = read_tip_poses(tmp_path / 'bag', '/tip_pose_truth')
    assert len(measured.t) == len(truth.t) == 4 * 180 + 1
    assert measured.frame_id == 'beam_base'
    noise = measured.z - truth.z
    assert np.std(noise) == pytest.approx(20e-6, rel=0.1)
    loads = read_load_events(tmp_path / 'bag')
    assert loads.t[0] == 0.0 and np.all(np.diff(loads.t) <= 1.0)
    changes = loads.changes()
    assert list(changes.kg) == [4.5, 0.0]
    assert changes.t[1] == 2.0


def test_latency_is_hidden_from_the_truth():
    options = SynthOptions(duration_s=3.0, effects={'sensor_latency': 0.02})
    measured, truth = simulate_experiment(BeamParameters(), DropTestConfig(), options)
    assert np.max(np.abs(measured.z - truth.z)) > 1e-3
    # The sample stamped t shows the beam as it was at t - 0.02 s.
    earlier = simulate_loads(BeamParameters(), truth.t - 0.02, [(2.0, 0.0)], 4.5)
    assert np.max(np.abs(measured.z - earlier.z)) < 1e-7


@pytest.mark.parametrize(
    ('text', 'message'),
    [
        ('coulomb_friction', 'expected NAME=VALUE'),
        ('gravity_wave=1', 'unknown effect'),
        ('added_mass=heavy', 'not a number'),
        ('added_mass=-0.3', r'mass_kg must be in \[0, 100\], got -0.3'),
        ('added_mass=nan', r'in \[0, 100\], got nan'),
        ('sensor_scale=0', r'scale must be in \(0, 10\]'),
        ('sensor_scale=-1.1', r'scale must be in \(0, 10\]'),
        ('mount_tilt=1.6', r'tilt_rad must be in \[-1.5, 1.5\]'),
        ('cubic_stiffness=inf', r'k3_nm_per_rad3 must be in \[-1e\+08, 1e\+09\], got inf'),
        ('cubic_stiffness=-1e12', r'k3_nm_per_rad3 must be in \[-1e\+08, 1e\+09\]'),
    ],
)
def test_bad_effects(text, message):
    with pytest.raises(LumpbeamError, match=message):
        parse_effect(text)


def test_good_effect():
    assert parse_effect('base_compliance=2e4') == ('base_compliance', 2e4)
    assert parse_effect('cubic_stiffness=-3e7') == ('cubic_stiffness', -3e7)
    assert parse_effect('mount_tilt=-0.05') == ('mount_tilt', -0.05)


def test_the_sensor_s_scale_is_hidden_from_the_truth():
    options = SynthOptions(duration_s=3.0, effects={'sensor_scale': 1.05, 'mount_tilt': 0.1})
    measured, truth = simulate_experiment(BeamParameters(), DropTestConfig(), options)
    tilted = with_effects(BeamParameters(), {'mount_tilt': 0.1})
    assert np.max(np.abs(truth.z - simulate_loads(tilted, truth.t, [(2.0, 0.0)], 4.5).z)) < 1e-12
    assert np.max(np.abs(measured.z - truth.z)) > 1e-3
    np.testing.assert_array_equal(measured.pitch, truth.pitch)


@pytest.mark.parametrize(
    'args',
    [
        ['--effect', 'nonsense=1'],
        ['--duration', '1.0'],  # ends before the release at 2 s
        ['--config', '/nonexistent.yaml'],
    ],
)
def test_cli_errors_are_one_line(tmp_path, capsys, args):
    assert main(['synth', str(tmp_path / 'bag'), *args]) == 2
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and err.startswith('lumpbeam synth: error:')
    assert not (tmp_path / 'bag').exists()


@pytest.mark.parametrize(
    ('args', 'message'),
    [
        (
            ['--duration', '1e9'],
            'duration 1e+09 s at 180 Hz (poses) is 1.8e+11 samples; the limit',
        ),
        (['--duration', '1e15', '--rate', '1e-9'], '(simulation grid) is 1.8e+17 samples'),
        (
            ['--duration', '3', '--tracker', '--tracker-rate', '1e12'],
            'duration 3 s at 1e+12 Hz (tracker) is 3e+12 samples; the limit is 500000',
        ),
        (
            ['--images', '--image-size', '100000x100000'],
            'image size 100000x100000: 10000000000 px; the limit is 16777216 px (4096x4096)',
        ),
    ],
)
def test_cli_refuses_what_needs_unbounded_memory(tmp_path, capsys, args, message):
    assert main(['synth', str(tmp_path / 'bag'), *args]) == 2
    err = capsys.readouterr().err
    assert err.count('\n') == 1 and err.startswith('lumpbeam synth: error:')
    assert message in err
    assert not (tmp_path / 'bag').exists()


def test_the_sample_limit_is_checked_before_simulating():
    with pytest.raises(LumpbeamError, match=f'the limit is {MAX_SAMPLES}'):
        check_sample_count(MAX_SAMPLES / 100.0 + 1e-6, {'poses': 100.0})
    check_sample_count(MAX_SAMPLES / 100.0, {'poses': 100.0})
    with pytest.raises(LumpbeamError, match='nan samples'):
        check_sample_count(math.nan, {'poses': 100.0})


def test_a_failed_write_leaves_no_partial_bag(tmp_path, monkeypatch):
    from lumpbeam_ros.core.synthetic import drop_test

    def fail(*_args, **_kwargs):
        raise KeyboardInterrupt  # what SIGTERM raises in `lumpbeam`

    monkeypatch.setattr(drop_test, 'write_scene', fail)
    with pytest.raises(KeyboardInterrupt):
        write_drop_test_bag(tmp_path / 'bag', BeamParameters(), DropTestConfig(), SynthOptions())
    assert not (tmp_path / 'bag').exists()
    (tmp_path / 'kept').mkdir()
    with pytest.raises(LumpbeamError, match='never overwritten'):
        write_drop_test_bag(tmp_path / 'kept', BeamParameters(), DropTestConfig(), SynthOptions())
    assert (tmp_path / 'kept').is_dir()  # an existing folder is not the writer's to remove


def test_cli_never_overwrites(tmp_path, capsys):
    (tmp_path / 'bag').mkdir()
    assert main(['synth', str(tmp_path / 'bag')]) == 2
    assert 'never overwritten' in capsys.readouterr().err


def test_cli_writes_a_bag(tmp_path, capsys):
    assert main(['synth', str(tmp_path / 'bag'), '--duration', '3', '--seed', '1']) == 0
    assert 'wrote' in capsys.readouterr().out
    assert len(read_tip_poses(tmp_path / 'bag').t) == 541
