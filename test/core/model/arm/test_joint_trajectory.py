"""Joint trajectories: interpolation, the CSV file read back exactly, and every bad file."""

import math

import numpy as np
import pytest

from lumpbeam_ros.base.errors import ConfigError, LumpbeamError
from lumpbeam_ros.core.model.arm.joint_trajectory import (
    JointTrajectory,
    read_trajectory_csv,
    write_trajectory_csv,
)


def _two_joints():
    return JointTrajectory(
        np.array([0.0, 1.0, 3.0]), np.array([[0.0, 1.0], [1.0, 1.0], [3.0, -1.0]])
    )


def test_default_names_and_read_only_arrays():
    traj = _two_joints()
    assert traj.joint_names == ('joint_1', 'joint_2')
    assert traj.joint_count == 2 and traj.duration_s == 3.0
    with pytest.raises(ValueError):
        traj.time_s[0] = 5.0
    with pytest.raises(ValueError):
        traj.angles_rad[0, 0] = 5.0


def test_one_joint_may_be_given_as_a_vector():
    traj = JointTrajectory([0.0, 2.0], [0.0, 4.0], ('shoulder',))
    assert traj.angles_rad.shape == (2, 1)
    assert traj.at(0.5).tolist() == [1.0]


@pytest.mark.parametrize(
    ('t', 'expected'),
    [
        (-5.0, [0.0, 1.0]),  # before the first row the first row holds
        (0.0, [0.0, 1.0]),
        (0.25, [0.25, 1.0]),
        (2.0, [2.0, 0.0]),  # halfway between rows 2 and 3
        (3.0, [3.0, -1.0]),
        (10.0, [3.0, -1.0]),  # after the last row the last holds
    ],
)
def test_at_interpolates_linearly_and_holds_the_ends(t, expected):
    assert _two_joints().at(t).tolist() == pytest.approx(expected, abs=1e-15)


def test_at_takes_arrays_of_any_shape():
    traj = _two_joints()
    times = np.array([[-1.0, 0.5], [2.0, 4.0]])
    angles = traj.at(times)
    assert angles.shape == (2, 2, 2)
    for index in np.ndindex(times.shape):
        assert angles[index].tolist() == traj.at(float(times[index])).tolist()


@pytest.mark.parametrize(
    ('time', 'angles', 'names', 'problem'),
    [
        ([0.0], [[1.0]], (), 'at least 2 samples'),
        ([0.0, 1.0], np.zeros((2, 0)), (), 'no joint'),
        ([0.0, 1.0], [[1.0], [2.0], [3.0]], (), '2 times for angles of shape (3, 1)'),
        ([0.0, math.nan], [[1.0], [2.0]], (), 'finite'),
        ([0.0, 1.0], [[1.0], [math.inf]], (), 'finite'),
        ([0.0, 1.0, 1.0], [[1.0], [2.0], [3.0]], (), 'sample 2 is at 1.0 s after 1.0 s'),
        ([0.0, 1.0], [[1.0, 2.0], [2.0, 3.0]], ('a',), '2 joints need as many distinct names'),
        ([0.0, 1.0], [[1.0, 2.0], [2.0, 3.0]], ('a', 'a'), 'distinct names'),
    ],
)
def test_bad_trajectories_are_refused_in_one_line(time, angles, names, problem):
    with pytest.raises(LumpbeamError) as caught:
        JointTrajectory(np.array(time), np.array(angles), names)
    assert problem in str(caught.value) and '\n' not in str(caught.value)


def test_file_round_trip_is_exact(tmp_path):
    rng = np.random.default_rng(3)
    time = np.cumsum(rng.uniform(1e-4, 1e-3, 500))
    traj = JointTrajectory(time, rng.normal(size=(500, 3)), ('a', 'b', 'c'))
    path = tmp_path / 'traj.csv'
    write_trajectory_csv(path, traj)
    assert path.read_text().splitlines()[0] == 'time_s,joint_1,joint_2,joint_3'
    back = read_trajectory_csv(path)
    assert np.array_equal(back.time_s, traj.time_s)
    assert np.array_equal(back.angles_rad, traj.angles_rad)
    assert back.joint_names == ('joint_1', 'joint_2', 'joint_3')


def test_file_tolerates_spaces_and_blank_lines(tmp_path):
    path = tmp_path / 'traj.csv'
    path.write_text('time_s, joint_1\n0, 0.5\n\n1e-3, -2\n\n')
    traj = read_trajectory_csv(path)
    assert traj.time_s.tolist() == [0.0, 1e-3]
    assert traj.angles_rad[:, 0].tolist() == [0.5, -2.0]


@pytest.mark.parametrize(
    ('text', 'problem'),
    [
        ('', 'empty, expected the header time_s,joint_1,...,joint_n'),
        ('time_s\n0\n1\n', 'header: expected time_s,joint_1,...,joint_n, got time_s'),
        ('joint_1,time_s\n0,0\n1,1\n', 'header: expected time_s,joint_1, got joint_1,time_s'),
        ('time_s,joint_2\n0,0\n1,1\n', 'header: expected time_s,joint_1, got time_s,joint_2'),
        ('time_s,joint_1,angle\n0,0,0\n', 'header: expected time_s,joint_1,joint_2, got'),
        ('0,0\n1,1\n', 'header: expected time_s,joint_1, got 0,0'),
        ('time_s,joint_1\n0,0\n1,1,2\n', 'line 3: 3 values for the 2 columns'),
        ('time_s,joint_1,joint_2\n0,0,0\n1,1\n', 'line 3: 2 values for the 3 columns'),
        ('time_s,joint_1\n0,0\n1,abc\n', "line 3: joint_1 is not a number: 'abc'"),
        ('time_s,joint_1\n0,0\n,1\n', "line 3: time_s is not a number: ''"),
        ('time_s,joint_1\n0,nan\n1,1\n', 'line 2: joint_1 is not finite: nan'),
        ('time_s,joint_1\n0,0\ninf,1\n', 'line 3: time_s is not finite: inf'),
        ('time_s,joint_1\n0,0\n1,1\n1,2\n', 'line 4: time_s must increase, 1.0 after 1.0'),
        ('time_s,joint_1\n0,0\n1,1\n0.5,2\n', 'line 4: time_s must increase, 0.5 after 1.0'),
        ('time_s,joint_1\n0,0\n', 'needs at least 2 rows, got 1'),
        ('time_s,joint_1\n', 'needs at least 2 rows, got 0'),
    ],
)
def test_bad_files_name_the_file_and_the_problem(tmp_path, text, problem):
    path = tmp_path / 'bad.csv'
    path.write_text(text)
    with pytest.raises(ConfigError) as caught:
        read_trajectory_csv(path)
    message = str(caught.value)
    assert message.startswith(f'{path}: ') and problem in message, message
    assert '\n' not in message


@pytest.mark.parametrize(
    ('name', 'problem'),
    [
        ('missing.csv', 'no such file'),
        ('x' * 300 + '.csv', 'cannot read it (File name too long)'),
        ('folder', 'cannot read it (Is a directory)'),
        ('binary.csv', 'not a text file'),
    ],
)
def test_unreadable_files_are_one_line(tmp_path, name, problem):
    (tmp_path / 'folder').mkdir()
    (tmp_path / 'binary.csv').write_bytes(b'time_s,joint_1\n\xff\xfe\x00\n')
    with pytest.raises(ConfigError) as caught:
        read_trajectory_csv(tmp_path / name)
    assert str(caught.value) == f'{tmp_path / name}: {problem}'


@pytest.mark.parametrize(
    ('name', 'problem'),
    [('x' * 300 + '.csv', 'File name too long'), ('no/such/dir.csv', 'No such file or directory')],
)
def test_unwritable_files_are_one_line(tmp_path, name, problem):
    with pytest.raises(LumpbeamError) as caught:
        write_trajectory_csv(tmp_path / name, _two_joints())
    assert str(caught.value) == f'cannot write {tmp_path / name}: {problem}'
