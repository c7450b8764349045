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
