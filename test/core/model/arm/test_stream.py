"""The arm stream: samples on the grid as the offline simulation gives them; bad commands."""

import numpy as np
import pytest
from arm_cases import small_arm

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model.arm.drive import SampledMotion
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.simulate import simulate_arm
from lumpbeam_ros.core.model.arm.stream import ArmStream

RATE = 100.0


@pytest.fixture(scope='module')
def model():
    return ArmModel.from_config(small_arm(2))


def _move(amplitude=(0.4, -0.3), duration=0.3, step=0.05):
    t = np.arange(0.0, duration + 1e-9, step)
    s = t / duration
    return t, np.outer(s - np.sin(2 * np.pi * s) / (2 * np.pi), amplitude)


def _drain(stream, start, end):
    parts = [stream.advance_to(now) for now in np.arange(start, end, 0.037)]
    return {k: np.concatenate([getattr(p, k) for p in parts]) for k in ('t', 'tip_z', 'q')}


def test_samples_are_the_offline_simulation_of_the_move(model):
    stream = ArmStream(model, RATE, ring_down_s=0.5)
    assert stream.advance_to(10.0).t.size == 0 and not stream.started
    t, q = _move()
    stream.command(['joint_2', 'joint_1'], t, q[:, ::-1], start_s=10.0)
    got = _drain(stream, 10.0, 11.2)
    # Every stamp once, on the grid, from the anchor on.
    assert np.allclose(np.diff(got['t']), 1 / RATE) and got['t'][0] == pytest.approx(10.0)
    assert got['t'][-1] > 11.0
    # Simulated in seconds from the anchor (10 s): the command's rows as it gave them.
    offline = simulate_arm(model, SampledMotion(JointTrajectory(t, q)), got['t'] - 10.0)
    np.testing.assert_allclose(got['q'], offline.q, atol=1e-12)
    assert np.max(np.abs(got['tip_z'] - offline.tip_z)) < 1e-7
    assert np.ptp(got['tip_z']) > 0.05


def test_a_second_command_inherits_the_vibration(model):
    stream = ArmStream(model, RATE, ring_down_s=0.4)
    t, q = _move()
    stream.command(['joint_1', 'joint_2'], t, q, start_s=0.0)
    first = _drain(stream, 0.0, 0.5)
    back = q[-1] - q
    stream.command(['joint_1', 'joint_2'], t + 0.05, back, start_s=0.5)
    second = _drain(stream, 0.5, 1.2)
    rows = JointTrajectory(np.concatenate([t, [0.5], 0.55 + t]), np.vstack([q, q[-1:], back]))
    stamps = np.concatenate([first['t'], second['t']])
    offline = simulate_arm(model, SampledMotion(rows), stamps)
    # The stream simulated the first move's history again with the second: the modal method's
    # windows fall elsewhere than in one offline run, so the two differ by its hold error
    # (micrometres), against the 0.1 m the tip travels and the mm it still rings.
    gap = np.abs(np.concatenate([first['tip_z'], second['tip_z']]) - offline.tip_z)
    assert np.max(gap) < 1e-5
    np.testing.assert_allclose(second['q'][-1], [0.0, 0.0], atol=1e-12)


def test_the_span_extends_and_the_history_is_bounded(model):
    stream = ArmStream(model, RATE, ring_down_s=0.5, history_s=1.0)
    t, q = _move()
    stream.command(['joint_1', 'joint_2'], t, q, start_s=0.0)
    got = _drain(stream, 0.0, 1.6)
    assert np.allclose(np.diff(got['t']), 1 / RATE)
    assert stream.anchor_s > 1.0  # re-anchored at rest at the held angles
    np.testing.assert_allclose(got['q'][-1], q[-1])


@pytest.mark.parametrize(
    ('names', 'times', 'positions', 'words'),
    [
        (['joint_1', 'joint_9'], [0.1], [[0.1, 0.2]], 'unknown joint name'),
        (['joint_1'], [0.1], [[0.1]], 'the arm has 2 joints'),
        (['joint_1', 'joint_1'], [0.1], [[0.1, 0.2]], 'each to be named once'),
        (['joint_1', 'joint_2'], [0.1], [[np.nan, 0.2]], 'finite'),
        (['joint_1', 'joint_2'], [0.2, 0.1], [[0.1, 0.2], [0.2, 0.3]], 'increase strictly'),
        (['joint_1', 'joint_2'], [0.1, 0.2], [[0.1, 0.2]], 'positions for 2 points'),
        (['joint_1', 'joint_2'], [0.0, 0.2], [[0.5, 0.2], [0.5, 0.2]], 'cannot jump'),
        (['joint_1', 'joint_2'], [], np.empty((0, 2)), 'no point'),
    ],
)
def test_bad_commands_are_refused_and_change_nothing(model, names, times, positions, words):
    stream = ArmStream(model, RATE, ring_down_s=0.2)
    stream.command(['joint_1', 'joint_2'], [0.0, 0.1], [[0.0, 0.0], [0.0, 0.0]], start_s=1.0)
    before = stream.motion
    with pytest.raises(LumpbeamError, match=words):
        stream.command(names, times, np.asarray(positions, dtype=float), start_s=1.05)
    assert stream.motion is before


def test_a_start_before_the_last_sample_is_refused(model):
    stream = ArmStream(model, RATE, ring_down_s=0.2)
    stream.command(['joint_1', 'joint_2'], [0.1], [[0.1, 0.0]], start_s=0.0)
    stream.advance_to(0.5)
    with pytest.raises(LumpbeamError, match='before the last sample'):
        stream.command(['joint_1', 'joint_2'], [0.1], [[0.1, 0.0]], start_s=0.2)


def test_commands_too_long_or_too_far_ahead_are_refused(model):
    stream = ArmStream(model, RATE, ring_down_s=0.2, history_s=5.0)
    with pytest.raises(LumpbeamError, match='longer than the history'):
        stream.command(['joint_1', 'joint_2'], [1e6], [[0.1, 0.0]], start_s=0.0)
    stream.command(['joint_1', 'joint_2'], [0.1], [[0.1, 0.0]], start_s=0.0)
    stream.advance_to(0.1)
    with pytest.raises(LumpbeamError, match='after the last sample'):
        stream.command(['joint_1', 'joint_2'], [0.1], [[0.1, 0.0]], start_s=1e9)


def test_a_restart_holds_the_joints_at_rest_from_the_new_time(model):
    stream = ArmStream(model, RATE, ring_down_s=0.3)
    t, q = _move()
    stream.command(['joint_1', 'joint_2'], t, q, start_s=5.0)
    stream.advance_to(5.2)
    stream.restart_at(2.0)  # a clock that jumped back: at rest at the angles held then
    got = _drain(stream, 2.0, 2.3)
    assert got['t'][0] == pytest.approx(2.0) and np.allclose(np.diff(got['t']), 1 / RATE)
    np.testing.assert_allclose(got['q'], 0.0)  # before the command's start: its first row
    assert np.ptp(got['tip_z']) < 1e-9  # at rest


def test_a_command_outside_a_joints_limits_is_refused_whatever_the_names_order():
    from dataclasses import replace

    arm = small_arm(2)
    limited = replace(
        arm, links=(arm.links[0], replace(arm.links[1], joint_limits_rad=(-0.5, 0.5)))
    )
    stream = ArmStream(ArmModel.from_config(limited), RATE, ring_down_s=0.2)
    stream.command(['joint_1', 'joint_2'], [0.1], [[0.9, 0.4]], start_s=0.0)
    before = stream.motion
    with pytest.raises(LumpbeamError, match=r'the command: joint_2 at 0\.6 rad is outside'):
        stream.command(['joint_2', 'joint_1'], [0.1, 0.2], [[0.4, 0.9], [0.6, 0.9]], start_s=0.5)
    assert stream.motion is before


@pytest.mark.parametrize('clock_s', [0.0, 1.7959e9])
def test_a_dense_command_on_todays_clock_is_simulated_as_at_time_zero(model, clock_s):
    # 1 kHz rows moved onto a clock of 1.8e9 s (2.4e-7 s resolution) stepped by jittering
    # intervals, whose splined rates shook a fast move's tip by a fraction of a millimetre.
    t = np.arange(0.0, 0.5 + 1e-9, 1e-3)
    s = t / 0.5
    q = np.outer(10 * s**3 - 15 * s**4 + 6 * s**5, [1.0, -1.2])
    start = clock_s + 0.25  # on the 100 Hz grid at 0, off it on the clock
    stream = ArmStream(model, RATE, ring_down_s=1.0)
    stream.command(['joint_1', 'joint_2'], t, q, start_s=start)
    got = _drain(stream, start, start + 1.2)
    offline = simulate_arm(model, SampledMotion(JointTrajectory(t, q)), got['t'] - start)
    # Its stamps still carry the clock's 2.4e-7 s: 0.2 um at the tip's speed, not 0.5 mm.
    assert np.max(np.abs(got['tip_z'] - offline.tip_z)) < 1e-6
    assert np.all(np.diff(got['t']) > 0.0)
