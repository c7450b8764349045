"""Each move shaped for the arm model's modes at its own end: moves, assembly, residuals."""

from dataclasses import replace

import numpy as np
import pytest
from arm_cases import minimum_jerk, small_arm

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.statics import arm_modes
from lumpbeam_ros.core.shaping.apply import shape_trajectory
from lumpbeam_ros.core.shaping.workspace import (
    WorkspaceShaper,
    predicted_residual,
    trajectory_moves,
)

ARM = small_arm(2)


def two_moves():
    """Out and back with a rest between: 0.3 s to (0.5, -0.8), 0.4 s rest, 0.25 s back."""
    out = minimum_jerk([0.0, 0.0], [0.5, -0.8], 0.3, before=0.1, after=0.4)
    back = minimum_jerk([0.5, -0.8], [-0.2, 0.6], 0.25, after=0.2)
    t = np.concatenate([out.time_s, out.time_s[-1] + 1e-3 + back.time_s])
    return JointTrajectory(t, np.vstack([out.angles_rad, back.angles_rad]))


def test_the_moves_of_a_file_run_between_its_rests():
    moves = trajectory_moves(two_moves())
    assert [(round(m.start_s, 3), round(m.end_s, 3)) for m in moves] == [
        (0.1, 0.4),
        (0.801, 1.051),
    ]
    assert moves[1].final_rad == pytest.approx([-0.2, 0.6])
    assert trajectory_moves(JointTrajectory([0.0, 1.0], [[0.3], [0.3]])) == ()


@pytest.fixture(scope='module')
def shaped_two_moves():
    trajectory = two_moves()
    return trajectory, *WorkspaceShaper(ARM, 'zvd', 2).shape(trajectory)


def test_each_move_is_shaped_for_the_modes_at_its_own_end(shaped_two_moves):
    _, _, moves = shaped_two_moves
    model = ArmModel.from_config(ARM)
    for move in moves:
        modes = arm_modes(model, move.final_q)
        assert [m.frequency_hz for m in move.modes] == pytest.approx(
            modes.natural_frequency_hz[:2], rel=1e-12
        )
    assert moves[0].modes[0].frequency_hz != pytest.approx(moves[1].modes[0].frequency_hz)
    assert all(m.reduction > 0.9 for m in moves)


def test_later_moves_start_later_by_the_time_added_and_rests_stay_at_rest(shaped_two_moves):
    trajectory, shaped, moves = shaped_two_moves
    first, second = (m.impulses.duration_s for m in moves)
    assert shaped.duration_s == pytest.approx(trajectory.duration_s + first + second, abs=1e-9)
    t, q = shaped.time_s, shaped.angles_rad
    # The rest between the moves: exactly at the first move's end, as long as it was.
    rest = (t > 0.4 + first + 1e-6) & (t < 0.801 + first - 1e-6)
    assert np.max(np.abs(q[rest] - [0.5, -0.8])) <= 1e-15
    moving = np.flatnonzero(np.any(np.abs(np.diff(q, axis=0)) > 0, axis=1))
    assert t[moving[0]] == pytest.approx(0.1, abs=2e-3)
    assert np.array_equal(q[-1], trajectory.angles_rad[-1])
    # The second move's shaped rows are its own shaping, delayed by the first's time added
    # (compared between two 1 kHz grids: within their interpolation, q'' h^2 / 8).
    alone = shape_trajectory(
        JointTrajectory(trajectory.time_s[801:1052], trajectory.angles_rad[801:1052]),
        moves[1].impulses,
    )
    delayed = np.interp(alone.time_s + first, t, q[:, 1])
    assert delayed == pytest.approx(alone.angles_rad[:, 1], abs=1e-5)


def test_a_fast_large_move_is_tuned_far_below_the_exact_shaper():
    # The elbow through 2.6 rad in 0.5 s: no fixed shaper cancels it (doc/arm.md).
    move = minimum_jerk([0.0, -1.3], [0.3, 1.3], 0.5)
    untuned = WorkspaceShaper(ARM, 'zvd', 2).shape_move(move)
    tuned = WorkspaceShaper(ARM, 'zvd', 2, tune=True).shape_move(move)
    assert untuned.reduction < 0.95
    assert tuned.reduction > 0.99
    assert tuned.predicted_residual_unshaped_m == untuned.predicted_residual_unshaped_m
    assert tuned.impulses.duration_s == pytest.approx(untuned.impulses.duration_s, abs=1e-12)
    assert np.all(tuned.impulses.amplitude > 0)
    assert tuned.impulses.amplitude.sum() == pytest.approx(1.0, abs=1e-12)
    assert np.all(np.diff(tuned.impulses.time_s) >= 0)
    # The residual the JSON reports is the model's for the impulses it gives.
    again = predicted_residual(ArmModel.from_config(ARM), shape_trajectory(move, tuned.impulses))
    assert again == tuned.predicted_residual_shaped_m


def test_the_json_of_a_move_has_the_contracts_keys(shaped_two_moves):
    entry = shaped_two_moves[2][0].as_json()
    assert set(entry) == {
        'start_s',
        'end_s',
        'final_q',
        'modes',
        'impulses',
        'duration_added_s',
        'predicted_residual_unshaped_m',
        'predicted_residual_shaped_m',
    }
    assert set(entry['modes'][0]) == {'natural_frequency_hz', 'damping_ratio'}


def test_a_file_without_a_move_comes_back_unchanged():
    still = JointTrajectory(np.arange(5) * 1e-3, np.full((5, 2), 0.4))
    shaped, moves = WorkspaceShaper(ARM).shape(still)
    assert moves == [] and np.array_equal(shaped.angles_rad, still.angles_rad)


def test_bad_input_is_one_line():
    with pytest.raises(LumpbeamError, match='the trajectory has 3 joints, the arm 2'):
        WorkspaceShaper(ARM).shape(minimum_jerk([0, 0, 0], [0.1, 0.1, 0.1], 0.2))
    limited = replace(
        ARM, links=(replace(ARM.links[0], joint_limits_rad=(-0.1, 0.1)), ARM.links[1])
    )
    with pytest.raises(LumpbeamError, match='joint_1 at 0.1.* rad is outside its limits'):
        WorkspaceShaper(limited).shape(two_moves())
    with pytest.raises(LumpbeamError, match='max modes must be 1 or more'):
        WorkspaceShaper(ARM, max_modes=0)
