"""Prescribed joint motions: linear between samples, held outside, rates by interval."""

import numpy as np
import pytest
from arm_cases import smooth_move

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model.arm.drive import SampledMotion


def test_sampled_motion_interpolates_holds_and_gives_slopes():
    motion = SampledMotion.from_arrays(
        np.array([0.0, 1.0, 3.0]), np.array([[0.0, 1.0], [1.0, 1.0], [0.0, 3.0]])
    )
    assert motion.n_joints == 2 and motion.end_time == 3.0
    assert motion.angles(0.5) == pytest.approx([0.5, 1.0])
    assert motion.angles(2.0) == pytest.approx([0.5, 2.0])
    assert motion.angles(-1.0) == pytest.approx([0.0, 1.0])
    assert motion.angles(9.0) == pytest.approx([0.0, 3.0])
    assert motion.rates(0.5) == pytest.approx([1.0, 0.0])
    assert motion.rates(1.0) == pytest.approx([-0.5, 1.0])  # a sample starts its interval
    assert motion.rates(-1.0) == pytest.approx([0.0, 0.0])
    assert motion.rates(3.0) == pytest.approx([0.0, 0.0])


def test_rates_are_the_derivative_of_the_angles_between_samples():
    t = np.linspace(0.0, 1.0, 11)
    motion = SampledMotion.from_arrays(t, np.sin(t)[:, None])
    h = 1e-6
    for time in (0.05, 0.43, 0.97):
        numeric = (motion.angles(time + h) - motion.angles(time - h)) / (2 * h)
        assert motion.rates(time) == pytest.approx(numeric, rel=1e-6)


def test_a_one_dimensional_array_is_one_joint():
    assert SampledMotion.from_arrays(np.array([0.0, 1.0]), np.array([0.0, 2.0])).n_joints == 1


@pytest.mark.parametrize(
    ('t', 'q', 'words'),
    [
        ([0.0, 1.0, 1.0], [[0.0], [1.0], [2.0]], 'increase'),
        ([0.0, 2.0, 1.0], [[0.0], [1.0], [2.0]], 'increase'),
        ([0.0, 1.0], [[0.0], [np.nan]], 'finite'),
        ([0.0, 1.0], [[0.0], [1.0], [2.0]], '2 times for angles'),
    ],
)
def test_bad_samples_are_one_line(t, q, words):
    with pytest.raises(LumpbeamError, match=words):
        SampledMotion.from_arrays(np.array(t), np.array(q))


def test_smooth_move_starts_and_ends_at_rest():
    move = smooth_move(np.array([0.5, -0.2]), 2.0)
    assert move.angles(0.0) == pytest.approx([0.0, 0.0])
    assert move.angles(5.0) == pytest.approx([0.5, -0.2])
    assert move.rates(0.0) == pytest.approx([0.0, 0.0], abs=1e-15)
    assert move.rates(2.0) == pytest.approx([0.0, 0.0], abs=1e-15)
    assert move.knots.size == 0


def test_the_spline_passes_through_the_samples_and_holds_the_ends():
    t = np.linspace(0.0, 1.0, 21)
    motion = SampledMotion.from_arrays(t, np.sin(3 * t))
    spline = motion.spline()
    for time in t[::4]:
        assert spline.angles(time) == pytest.approx(motion.angles(time), abs=1e-14)
    # Between samples it follows the sampled sine (O(h^4)), the straight lines do not (h^2).
    middle = 0.5 + 1 / 40
    assert spline.angles(middle) == pytest.approx([np.sin(3 * middle)], abs=1e-5)
    assert abs(motion.angles(middle)[0] - np.sin(3 * middle)) > 1e-3
    assert spline.angles(7.0) == pytest.approx(motion.angles(1.0))
    assert spline.rates(7.0) == pytest.approx([0.0])
    assert spline.knots.tolist() == [0.0, 1.0]


def _move_with_holds(wobble=False):
    """Held 0.3 s, a 1 kHz minimum-jerk move, held 2 s, one straight step, held again."""
    t = np.linspace(0.0, 0.5, 501)
    s = t / 0.5
    s = 10 * s**3 - 15 * s**4 + 6 * s**5
    times = np.concatenate([[0.0], 0.3 + t, [2.8, 2.9, 4.0]])
    angles = np.concatenate([[0.0], s, [1.0, 1.2, 1.2]])
    if wobble:  # a hold as sums give it: an ulp off
        angles[-2] = np.nextafter(1.2, 2.0)
        angles[-4] = np.nextafter(1.0, 0.0)
    return SampledMotion.from_arrays(times, angles)


@pytest.mark.parametrize('wobble', [False, True])
def test_the_spline_keeps_every_hold_still(wobble):
    # One spline through it all wiggled the joint 0.6 mrad during the 0.3 s hold before the
    # move, and moved it during the 2 s hold after.
    spline = _move_with_holds(wobble).spline()
    before = np.linspace(0.0, 0.3, 301)
    after = np.linspace(0.8, 2.8, 302)[:-1]  # 2.8: the step starts
    q, q_dot, _ = spline.sample(np.concatenate([before, after]))
    assert np.abs(q[:301]).max() < 1e-12 and np.abs(q[301:] - 1.0).max() < 1e-12
    assert np.abs(q_dot).max() < 1e-9
    # The move itself: the minimum-jerk profile within the spline's O(h^4), at rest at both
    # ends where it meets the holds.
    t = np.linspace(0.3, 0.8, 1001)
    s = (t - 0.3) / 0.5
    exact = 10 * s**3 - 15 * s**4 + 6 * s**5
    assert np.abs(spline.sample(t)[0][:, 0] - exact).max() < 1e-9
    assert np.abs(spline.rates(0.3)).max() < 1e-9 and np.abs(spline.rates(0.8)).max() < 1e-9


def test_a_lone_step_stays_a_straight_line_its_rate_jumping_at_both_ends():
    spline = _move_with_holds().spline()
    assert spline.angles(2.85) == pytest.approx([1.1])
    assert spline.rates(2.85) == pytest.approx([2.0])
    assert {2.8, 2.9} <= set(spline.knots.tolist())
