"""Shaped trajectories: exact sums of shifted commands, sampling, and the vibration removed.

The vibration is simulated by a model that shares nothing with the shapers (one or two damped
modes driven by the commanded angle, integrated by scipy.signal.lsim); the residual is the RMS
distance from the final rest from the end of the move to 3 s after. Shaped moves of the
flexible arm, in its own model and in MuJoCo, are test/core/shaping/test_on_arm.py's.
"""

import math

import numpy as np
import pytest
from scipy import signal

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.shaping.apply import MAX_SAMPLES, shape_trajectory, shaped_times
from lumpbeam_ros.core.shaping.impulses import Impulses, Mode
from lumpbeam_ros.core.shaping.shapers import design_shaper


def _move(duration_s=0.1, rate_hz=1000.0, joints=1):
    """A rest-to-rest move of 0.5 rad per joint, smooth (cycloidal), sampled at rate_hz."""
    t = np.arange(int(round(duration_s * rate_hz)) + 1) / rate_hz
    s = t / duration_s
    angle = 0.5 * (s - np.sin(2 * np.pi * s) / (2 * np.pi))
    return JointTrajectory(t, np.column_stack([angle * (j + 1) for j in range(joints)]))


@pytest.mark.parametrize(
    'move',
    [
        _move(joints=2),  # even at 1 kHz: the fractional-delay path
        _move(rate_hz=4000.0, joints=2),
        _move(rate_hz=100.0, joints=2),  # coarser than 1 kHz: interpolated
        JointTrajectory([0.0, 0.013, 0.02, 0.1], [[0.0, 1.0], [0.2, 0.5], [0.3, 0.1], [0.5, 0]]),
    ],
    ids=['1kHz', '4kHz', '100Hz', 'uneven'],
)
def test_shaped_angles_are_the_weighted_sum_of_the_delayed_command(move):
    impulses = Impulses([0.0, 0.0371, 0.09], [0.2, 0.5, 0.3])
    shaped = shape_trajectory(move, impulses)
    expected = sum(
        a * move.at(shaped.time_s - t)
        for t, a in zip([0.0, 0.0371, 0.09], [0.2, 0.5, 0.3], strict=True)
    )
    assert np.allclose(shaped.angles_rad, expected, rtol=0, atol=1e-12)
    assert shaped.joint_names == move.joint_names


@pytest.mark.parametrize('rate_hz', [1000.0, 100.0])  # the fractional-delay path, resampled
@pytest.mark.parametrize('mode', [Mode(2.0, 0.05), Mode(3.0123, 0.0071)])
def test_shaped_move_starts_and_ends_at_rest_at_exactly_the_same_angles(rate_hz, mode):
    move = _move(rate_hz=rate_hz, joints=3)
    impulses = design_shaper('zvd', [mode])
    shaped = shape_trajectory(move, impulses)
    assert shaped.time_s[0] == move.time_s[0]
    assert shaped.time_s[-1] == pytest.approx(move.time_s[-1] + impulses.duration_s, abs=1e-12)
    np.testing.assert_array_equal(shaped.angles_rad[0], move.angles_rad[0])
    np.testing.assert_array_equal(shaped.angles_rad[-1], move.angles_rad[-1])
    assert np.max(np.diff(shaped.time_s)) <= 1e-3 + 1e-15


@pytest.mark.parametrize('rate_hz', [1000.0, 4000.0])
def test_an_even_input_at_1_khz_or_finer_keeps_its_grid(rate_hz):
    move = _move(rate_hz=rate_hz)
    impulses = design_shaper('zv', [Mode(3.0, 0.0)])
    times = shaped_times(move, impulses.duration_s)
    assert np.allclose(times[: move.time_s.size], move.time_s, rtol=0, atol=1e-12)
    steps = np.diff(times)
    assert np.allclose(steps[:-1], 1 / rate_hz, rtol=1e-9, atol=0)
    assert 0 < steps[-1] <= 1 / rate_hz * (1 + 1e-9)
    assert times[-1] == move.time_s[-1] + impulses.duration_s


@pytest.mark.parametrize('times', [np.arange(11) * 0.01, np.array([0.0, 0.0007, 0.001, 0.0041])])
def test_other_inputs_are_resampled_evenly_at_1_khz_or_their_median_interval(times):
    move = JointTrajectory(times, times * 2)
    impulses = design_shaper('zv', [Mode(3.0, 0.0)])
    steps = np.diff(shaped_times(move, impulses.duration_s))
    step = min(1e-3, float(np.median(np.diff(times))))
    # Evenly spaced, the step shrunk just enough to end on the last time.
    assert np.ptp(steps) < 1e-12
    assert step * 0.99 < steps[0] <= step * (1 + 1e-12)


def test_too_low_a_frequency_is_refused_before_allocating():
    with pytest.raises(LumpbeamError) as caught:
        shape_trajectory(_move(), design_shaper('zv', [Mode(1e-5, 0.0)]))
    assert f'more than {MAX_SAMPLES}: is the frequency too low?' in str(caught.value)


def _residual_rms(command, modes, weights):
    """RMS tip vibration from the end of the command to 3 s after, of weighted modes."""
    end = command.time_s[-1]
    t = np.arange(0.0, end + 3.0, 2e-4)
    u = command.at(t)[:, 0]
    x = np.zeros_like(t)
    for mode, weight in zip(modes, weights, strict=True):
        omega = 2 * math.pi * mode.frequency_hz
        lti = signal.lti([omega**2], [1.0, 2 * mode.damping_ratio * omega, omega**2])
        x += weight * signal.lsim(lti, u, t)[1]
    after = t >= end
    return float(np.sqrt(np.mean((x[after] - command.angles_rad[-1, 0]) ** 2)))


ONE = [Mode(2.0, 0.02)]
TWO = [Mode(2.0, 0.02), Mode(7.3, 0.03)]


@pytest.mark.parametrize(
    ('kind', 'designed', 'actual', 'weights', 'least_reduction'),
    [
        ('zv', ONE, ONE, [1.0], 0.90),
        ('zvd', ONE, ONE, [1.0], 0.95),
        ('ei', ONE, ONE, [1.0], 0.90),
        ('zvd', ONE, [Mode(2.3, 0.02)], [1.0], 0.85),
        ('zvd', ONE, [Mode(1.7, 0.02)], [1.0], 0.85),
        ('ei', ONE, [Mode(2.3, 0.02)], [1.0], 0.85),
        ('ei', ONE, [Mode(1.7, 0.02)], [1.0], 0.85),
        ('zv', TWO, TWO, [0.7, 0.3], 0.90),
        ('zvd', TWO, TWO, [0.7, 0.3], 0.95),
    ],
)
def test_residual_vibration_drops(kind, designed, actual, weights, least_reduction):
    move = _move()
    shaped = shape_trajectory(move, design_shaper(kind, designed))
    before = _residual_rms(move, actual, weights)
    after = _residual_rms(shaped, actual, weights)
    assert before > 0.05  # the unshaped move rings
    assert 1 - after / before >= least_reduction
