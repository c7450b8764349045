"""``lumpbeam synth --arm --trajectory``: the bag's topics, stamps, truth and noise; bad input."""

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml
from arm_cases import small_arm
from rosbags.highlevel import AnyReader

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.bagio import read_tip_poses
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory, write_trajectory_csv
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.synthetic.arm_bag import (
    ArmSynthOptions,
    board_at_rest,
    rest_tip_pose,
    simulate_arm_record,
    write_arm_bag,
)
from lumpbeam_ros.core.vision.config import load_camera_config
from lumpbeam_ros.core.vision.geometry import rotation_y
from lumpbeam_ros.core.vision.pose import PlaneModel


def _move(joints: int, start: float = 0.0) -> JointTrajectory:
    t = np.arange(0.0, 0.3 + 1e-9, 1e-3)
    s = t / 0.3
    profile = s - np.sin(2 * np.pi * s) / (2 * np.pi)
    return JointTrajectory(start + t, np.outer(profile, [0.4, -0.5, 0.3][:joints]))


def _joint_states(bag: Path) -> tuple[np.ndarray, list[list[str]], np.ndarray]:
    with AnyReader([bag]) as reader:
        connections = [c for c in reader.connections if c.topic == '/joint_states']
        assert [c.msgtype for c in connections] == ['sensor_msgs/msg/JointState']
        rows = [reader.deserialize(raw, c.msgtype) for c, _, raw in reader.messages(connections)]
    stamps = np.array([m.header.stamp.sec + 1e-9 * m.header.stamp.nanosec for m in rows])
    return stamps, [list(m.name) for m in rows], np.array([m.position for m in rows])


def test_the_bag_holds_commanded_angles_noisy_poses_and_truth(tmp_path):
    move = _move(2)
    options = ArmSynthOptions(duration_s=0.6, seed=4, noise_m=1e-4)
    motion = write_arm_bag(tmp_path / 'bag', small_arm(2), move, options)
    stamps, names, angles = _joint_states(tmp_path / 'bag')
    assert stamps.size == int(0.6 * 180) + 1 and stamps[0] == 0.0
    assert stamps == pytest.approx(np.arange(stamps.size) / 180.0, abs=1e-9)
    assert names[0] == ['joint_1', 'joint_2']
    assert angles == pytest.approx(move.at(np.arange(stamps.size) / 180.0), abs=1e-12)
    truth = read_tip_poses(tmp_path / 'bag', '/tip_pose_truth')
    measured = read_tip_poses(tmp_path / 'bag')
    assert truth.t == pytest.approx(stamps, abs=1e-9)
    assert truth.z == pytest.approx(motion.tip_z, abs=1e-12)
    assert np.std(measured.z - truth.z) == pytest.approx(1e-4, rel=0.25)
    # The arm moved its tip and was still vibrating after the move.
    assert np.ptp(truth.x) > 0.1
    after = truth.t > 0.3
    assert np.ptp(truth.z[after]) > 1e-5


def test_the_record_starts_at_rest_at_the_first_row():
    motion = simulate_arm_record(small_arm(2), _move(2), ArmSynthOptions(duration_s=0.3))
    assert np.abs(motion.phi_dot[0]).max() == 0.0
    assert motion.q[0] == pytest.approx([0.0, 0.0])


@pytest.mark.parametrize(
    ('joints', 'duration', 'start', 'words'),
    [
        (3, 1.0, 0.0, 'trajectory has 3 joints, the arm 2'),
        (2, 0.2, 0.0, 'shorter than the trajectory'),
        (2, 1.0, -1.0, 'cannot be negative'),
        (2, 1e6, 0.0, 'the limit is'),
    ],
)
def test_bad_inputs_are_one_line(tmp_path, joints, duration, start, words):
    with pytest.raises(LumpbeamError, match=words):
        write_arm_bag(
            tmp_path / 'bag',
            small_arm(2),
            _move(joints, start),
            ArmSynthOptions(duration_s=duration),
        )
    assert not (tmp_path / 'bag').exists()


def test_a_trajectory_outside_a_joints_limits_writes_no_bag(tmp_path):
    arm = small_arm(2)
    limited = replace(arm, links=(arm.links[0], replace(arm.links[1], joint_limits_rad=(-0.4, 1))))
    with pytest.raises(
        LumpbeamError,
        match=r'the trajectory: joint_2 at -0.40\d* rad is outside its limits \[-0.4, 1\]',
    ):
        write_arm_bag(tmp_path / 'bag', limited, _move(2), ArmSynthOptions(duration_s=1.0))
    assert not (tmp_path / 'bag').exists()


@pytest.fixture
def files(tmp_path):
    arm = tmp_path / 'arm.yaml'
    links = [
        {'length_m': 1.0, 'n_segments': 3, 'ei_nm2': 500.0, 'mass_kg': 1.0},
        {'length_m': 0.5, 'n_segments': 2, 'ei_nm2': 300.0, 'mass_kg': 0.4},
    ]
    arm.write_text(yaml.safe_dump({'arm': {'links': links}}))
    trajectory = tmp_path / 'move.csv'
    write_trajectory_csv(trajectory, _move(2))
    return arm, trajectory


def test_the_command_writes_the_bag(tmp_path, files, capsys):
    arm, trajectory = files
    argv = ['synth', str(tmp_path / 'out'), '--arm', str(arm), '--trajectory', str(trajectory)]
    assert main([*argv, '--duration', '0.5', '--noise', '0']) == 0
    assert 'wrote' in capsys.readouterr().out
    truth = read_tip_poses(tmp_path / 'out', '/tip_pose_truth')
    measured = read_tip_poses(tmp_path / 'out')
    assert measured.z == pytest.approx(truth.z, abs=1e-12)


@pytest.mark.parametrize(
    ('extra', 'words'),
    [
        (['--trajectory', None], '--arm and --trajectory go together'),
        (['--arm', None], '--arm and --trajectory go together'),
        (['--arm', 'A', '--trajectory', 'T', '--tracker'], '--tracker: not for an arm'),
        (['--arm', 'A', '--trajectory', 'T', '--images', '--image-size', '9x9'], 'at least 64'),
        (['--arm', 'A', '--trajectory', 'T', '--effect', 'added_mass=1'], '--effect'),
        (['--arm', 'A', '--trajectory', 'T', '--duration', '0.1'], 'shorter than'),
        (['--arm', 'missing.yaml', '--trajectory', 'T'], 'no such file'),
    ],
)
def test_bad_command_lines_are_one_line_exit_2(tmp_path, files, capsys, extra, words):
    arm, trajectory = files
    given = {'A': str(arm), 'T': str(trajectory), None: str(trajectory)}
    extra = [given.get(x, x) if x in given else x for x in extra]
    if extra[:2] == ['--arm', str(trajectory)]:
        extra[1] = str(arm)
    assert main(['synth', str(tmp_path / 'out'), *extra]) == 2
    err = capsys.readouterr().err
    assert words in err and err.count('\n') == 1


def test_the_board_faces_the_tip_camera_at_rest_after_the_move():
    model = ArmModel.from_config(small_arm(3))
    tip = rest_tip_pose(model, np.array([0.4, -0.5, 0.3]))
    assert abs(tip[2]) > 0.1  # the tip is turned: the board must turn with it
    params, placed = board_at_rest(None, tip)
    default = load_camera_config()
    np.testing.assert_allclose(
        placed.rig.base_board.rotation, rotation_y(tip[2]) @ default.rig.base_board.rotation
    )
    assert params['board.xyz_m'] == pytest.approx([tip[0], 1.0, tip[1]])
    # From that pose the camera sees the board as the beam rig's camera sees its own board
    # from the pose straight across from it.
    seen = PlaneModel(placed.rig, placed.camera_info).project(np.array(tip))
    centre = default.rig.base_board.translation
    beam = PlaneModel(default.rig, default.camera_info).project(
        np.array([centre[0], centre[2], 0.0])
    )
    np.testing.assert_allclose(seen, beam, atol=1e-6)


@pytest.mark.slow
def test_track_recovers_the_tip_pose_once_the_arm_has_stopped(tmp_path, capsys):
    """``synth --arm --images`` then ``track``: prints the errors (``pytest -m slow -s``)."""
    move = tmp_path / 'move.csv'
    t = np.arange(0.0, 0.5 + 1e-9, 1e-3)
    s = t / 0.5
    write_trajectory_csv(
        move, JointTrajectory(t, (s - np.sin(2 * np.pi * s) / (2 * np.pi))[:, None] * 0.8)
    )
    bag, out = tmp_path / 'bag', tmp_path / 'tracked'
    arm = Path(__file__).resolve().parents[3] / 'config' / 'arm_rotary.yaml'
    argv = ['synth', str(bag), '--arm', str(arm), '--trajectory', str(move)]
    assert main([*argv, '--duration', '2', '--images', '--image-size', '320x240']) == 0
    assert f'--config {bag}/camera.yaml' in capsys.readouterr().out
    assert main(['track', str(bag), str(out), '--config', str(bag / 'camera.yaml')]) == 0
    tracked = read_tip_poses(out)
    truth = read_tip_poses(bag, '/tip_pose_truth')
    index = np.searchsorted(truth.t, tracked.t)
    assert np.allclose(truth.t[index], tracked.t, atol=1e-9)
    # The board is in view once the arm has stopped: every frame after the move is tracked.
    after = truth.t > 0.5
    assert np.isin(truth.t[after], tracked.t).all()
    print(f'\n{tracked.t.size} of {truth.t.size} frames tracked (the board in view)')
    for name, unit, scale in (('x', 'um', 1e6), ('z', 'um', 1e6), ('pitch', 'urad', 1e6)):
        error = (getattr(tracked, name) - getattr(truth, name)[index]) * scale
        rms = np.sqrt(np.mean(error**2))
        print(
            f'  {name}: RMS {rms:.2f} {unit} (bias {error.mean():.2f}, std {error.std():.2f}, '
            f'max {np.abs(error).max():.2f})'
        )
        assert rms < (100.0 if name == 'pitch' else 30.0)
