"""``lumpbeam shape``: the shaped file and its JSON, the modes by option or file, bad input."""

import json

import numpy as np
import pytest
import yaml
from arm_cases import minimum_jerk, small_arm_document

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.core.model.arm.joint_trajectory import (
    JointTrajectory,
    read_trajectory_csv,
    write_trajectory_csv,
)
from lumpbeam_ros.core.shaping.apply import shape_trajectory
from lumpbeam_ros.core.shaping.impulses import Mode
from lumpbeam_ros.core.shaping.shapers import design_shaper


@pytest.fixture
def move(tmp_path):
    t = np.arange(101) * 1e-3
    path = tmp_path / 'move.csv'
    write_trajectory_csv(path, JointTrajectory(t, np.column_stack([t * 5, -t * 2])))
    return path


@pytest.mark.parametrize('kind', ['zv', 'zvd', 'ei'])
def test_writes_the_shaped_file_and_the_json(tmp_path, move, kind, capsys):
    out, report = tmp_path / 'shaped.csv', tmp_path / 'shape.json'
    argv = ['shape', str(move), str(out), '--shaper', kind, '--json', str(report)]
    argv += ['--frequency-hz', '2.5', '--damping-ratio', '0.02']
    argv += ['--frequency-hz', '9', '--damping-ratio', '0.04']
    assert main(argv) == 0
    expected_impulses = design_shaper(kind, [Mode(2.5, 0.02), Mode(9.0, 0.04)])
    expected = shape_trajectory(read_trajectory_csv(move), expected_impulses)
    shaped = read_trajectory_csv(out)
    assert np.array_equal(shaped.time_s, expected.time_s)
    assert np.array_equal(shaped.angles_rad, expected.angles_rad)
    data = json.loads(report.read_text())
    assert data['impulses'] == expected_impulses.as_list()
    assert data['duration_added_s'] == expected_impulses.duration_s
    assert sum(i['amplitude'] for i in data['impulses']) == pytest.approx(1.0, abs=1e-12)
    assert [m['natural_frequency_hz'] for m in data['modes']] == [2.5, 9.0]
    printed = capsys.readouterr().out
    assert f'{kind.upper()} shaper for 2 mode(s)' in printed and 'mode 2: 9 Hz' in printed


def test_one_damping_ratio_serves_every_mode_and_defaults_to_zero(tmp_path, move):
    out = tmp_path / 'a.csv'
    assert main(['shape', str(move), str(out), '--frequency-hz', '3', '--frequency-hz', '8']) == 0
    zero = read_trajectory_csv(out)
    expected = shape_trajectory(
        read_trajectory_csv(move), design_shaper('zvd', [Mode(3.0, 0.0), Mode(8.0, 0.0)])
    )
    assert np.array_equal(zero.angles_rad, expected.angles_rad)
    argv = ['shape', str(move), str(out), '--frequency-hz', '3', '--frequency-hz', '8']
    assert main([*argv, '--damping-ratio', '0.05']) == 0
    expected = shape_trajectory(
        read_trajectory_csv(move), design_shaper('zvd', [Mode(3.0, 0.05), Mode(8.0, 0.05)])
    )
    assert np.array_equal(read_trajectory_csv(out).angles_rad, expected.angles_rad)


def test_modes_from_the_json_of_analyze(tmp_path, move):
    params = tmp_path / 'params.json'
    params.write_text(
        json.dumps(
            {
                'natural_frequency_hz': 3.1,
                'damping_ratio': 0.01,
                'modes': [
                    {'natural_frequency_hz': 3.1, 'damping_ratio': 0.01},
                    {'natural_frequency_hz': 17.0, 'damping_ratio': 0.02},
                ],
            }
        )
    )
    report = tmp_path / 'r.json'
    argv = ['shape', str(move), str(tmp_path / 'o.csv'), '--params', str(params)]
    assert main([*argv, '--json', str(report)]) == 0
    expected = design_shaper('zvd', [Mode(3.1, 0.01), Mode(17.0, 0.02)])
    assert json.loads(report.read_text())['impulses'] == expected.as_list()


@pytest.mark.parametrize(
    ('options', 'problem'),
    [
        (['--frequency-hz', '0'], 'mode 1 (--frequency-hz 0.0): natural frequency must be'),
        (['--frequency-hz', '-2'], 'mode 1 (--frequency-hz -2.0): natural frequency must be'),
        (['--frequency-hz', 'nan'], 'mode 1 (--frequency-hz nan): natural frequency must be'),
        (
            ['--frequency-hz', '2', '--damping-ratio', '1'],
            'mode 1 (--frequency-hz 2.0): damping ratio must be in [0, 1)',
        ),
        (
            ['--frequency-hz', '2', '--damping-ratio', '-0.1'],
            'mode 1 (--frequency-hz 2.0): damping ratio must be in [0, 1)',
        ),
        (
            ['--frequency-hz', '2', '--damping-ratio', 'nan'],
            'mode 1 (--frequency-hz 2.0): damping ratio must be in [0, 1)',
        ),
        (
            ['--frequency-hz', '2', '--frequency-hz', '3', '--frequency-hz', '4']
            + ['--damping-ratio', '0.1', '--damping-ratio', '0.1'],
            '3 --frequency-hz for 2 --damping-ratio: give one damping ratio per frequency',
        ),
        ([], 'give the modes: --frequency-hz F [--damping-ratio Z] or --params'),
        (['--damping-ratio', '0.1'], '--damping-ratio needs --frequency-hz'),
        (
            ['--frequency-hz', '2', '--params', 'p.json'],
            'give the modes by --params or by --frequency-hz, not both',
        ),
        (['--params', 'missing.json'], 'missing.json: no such file'),
        (
            ['--shaper', 'ei', '--frequency-hz', '2', '--damping-ratio', '0.7'],
            'EI shaper: damping ratio 0.7 is above 0.5',
        ),
        (['--frequency-hz', '1e-6'], 'is the frequency too low?'),
    ],
)
def test_bad_modes_are_one_line(tmp_path, move, capsys, options, problem):
    out = tmp_path / 'o.csv'
    assert main(['shape', str(move), str(out), *options]) == 2
    err = capsys.readouterr().err
    assert err.startswith('lumpbeam shape: error: ') and problem in err, err
    assert err.count('\n') == 1
    assert not out.exists()


@pytest.mark.parametrize(
    ('text', 'problem'),
    [
        ('time_s,joint_1\n0,0\n', 'needs at least 2 rows, got 1'),
        ('time_s,joint_1\n0,0\n0,1\n', 'line 3: time_s must increase'),
        ('time,joint_1\n0,0\n1,1\n', 'header: expected time_s,joint_1'),
    ],
)
def test_bad_trajectories_are_one_line(tmp_path, capsys, text, problem):
    source = tmp_path / 'in.csv'
    source.write_text(text)
    assert main(['shape', str(source), str(tmp_path / 'o.csv'), '--frequency-hz', '2']) == 2
    err = capsys.readouterr().err
    assert err.startswith(f'lumpbeam shape: error: {source}: ') and problem in err, err
    assert err.count('\n') == 1


def test_unwritable_output_is_one_line(tmp_path, move, capsys):
    out = tmp_path / 'no' / 'such' / 'o.csv'
    assert main(['shape', str(move), str(out), '--frequency-hz', '2']) == 2
    assert capsys.readouterr().err == (
        f'lumpbeam shape: error: cannot write {out}: No such file or directory\n'
    )


def test_a_non_number_is_a_usage_error(tmp_path, move, capsys):
    with pytest.raises(SystemExit) as caught:
        main(['shape', str(move), str(tmp_path / 'o.csv'), '--frequency-hz', 'fast'])
    assert caught.value.code == 2
    assert "invalid float value: 'fast'" in capsys.readouterr().err


@pytest.fixture(scope='module')
def arm_files(tmp_path_factory):
    """small_arm(2)'s file and a two-move trajectory for it (out, rest, back)."""
    root = tmp_path_factory.mktemp('shape_arm')
    arm = root / 'arm.yaml'
    arm.write_text(yaml.safe_dump(small_arm_document(2)))
    out = minimum_jerk([0.0, 0.0], [0.5, -0.8], 0.3, before=0.1, after=0.4)
    back = minimum_jerk([0.5, -0.8], [-0.2, 0.6], 0.25, after=0.2)
    t = np.concatenate([out.time_s, out.time_s[-1] + 1e-3 + back.time_s])
    moves = root / 'moves.csv'
    write_trajectory_csv(moves, JointTrajectory(t, np.vstack([out.angles_rad, back.angles_rad])))
    return arm, moves


@pytest.mark.parametrize('tune', [False, True], ids=['untuned', 'tuned'])
def test_each_move_is_shaped_by_the_arms_model(tmp_path, arm_files, capsys, tune):
    arm, moves = arm_files
    out, report = tmp_path / 'shaped.csv', tmp_path / 'shape.json'
    argv = ['shape', str(moves), str(out), '--arm', str(arm), '--json', str(report)]
    assert main(argv + (['--tune'] if tune else [])) == 0
    data = json.loads(report.read_text())
    assert len(data['moves']) == 2 and data['tuned'] is tune
    first, second = data['moves']
    assert first['final_q'] == pytest.approx([0.5, -0.8])
    assert len(first['modes']) == 2
    for move in data['moves']:
        assert move['predicted_residual_shaped_m'] < 0.1 * move['predicted_residual_unshaped_m']
    shaped = read_trajectory_csv(out)
    added = first['duration_added_s'] + second['duration_added_s']
    assert data['duration_added_s'] == pytest.approx(added)
    assert shaped.time_s[-1] == pytest.approx(read_trajectory_csv(moves).time_s[-1] + added)
    printed = capsys.readouterr().out
    assert 'move 2: 0.801-1.051 s' in printed and '% less)' in printed


def test_the_payload_option_changes_the_modes(tmp_path, arm_files):
    arm, moves = arm_files
    modes = []
    for payload in ('0', '2'):
        report = tmp_path / f'{payload}.json'
        argv = ['shape', str(moves), str(tmp_path / 'o.csv'), '--arm', str(arm)]
        assert (
            main([*argv, '--payload-kg', payload, '--max-modes', '1', '--json', str(report)]) == 0
        )
        (mode,) = json.loads(report.read_text())['moves'][0]['modes']
        modes.append(mode['natural_frequency_hz'])
    assert modes[1] < 0.8 * modes[0]


@pytest.mark.parametrize(
    ('options', 'problem'),
    [
        (['--tune'], '--tune: only with --arm FILE'),
        (['--payload-kg', '1', '--max-modes', '1'], '--payload-kg, --max-modes: only with --arm'),
        (['--arm', 'ARM', '--frequency-hz', '2'], 'not with --frequency-hz, --damping-ratio'),
        (['--arm', 'missing.yaml'], 'missing.yaml: no such file'),
        (['--arm', 'ARM3'], 'the trajectory has 2 joints, the arm 3'),
        (
            ['--arm', 'LIMITED'],
            'joint_2 at -0.503636 rad is outside its limits [-0.5, 1] rad',
        ),
    ],
)
def test_bad_input_by_the_model_is_one_line(tmp_path, arm_files, capsys, options, problem):
    arm, moves = arm_files
    three = tmp_path / 'three.yaml'
    three.write_text(yaml.safe_dump(small_arm_document(3)))
    document = small_arm_document(2)
    document['arm']['links'][1]['joint_limits_rad'] = [-0.5, 1.0]
    limited = tmp_path / 'limited.yaml'
    limited.write_text(yaml.safe_dump(document))
    names = {'ARM': str(arm), 'ARM3': str(three), 'LIMITED': str(limited)}
    out = tmp_path / 'o.csv'
    assert main(['shape', str(moves), str(out), *(names.get(o, o) for o in options)]) == 2
    err = capsys.readouterr().err
    assert err.startswith('lumpbeam shape: error: ') and problem in err, err
    assert err.count('\n') == 1
    assert not out.exists()
