import numpy as np
import pytest

from lumpbeam_ros.core.vision.geometry import (
    Transform,
    pitch_quaternion,
    rotation_y,
    tip_pose_from_transform,
    tip_transform,
)


def test_positive_pitch_points_the_tip_down():
    x_axis = rotation_y(0.1) @ np.array([1.0, 0.0, 0.0])
    assert x_axis[2] == pytest.approx(-np.sin(0.1))


@pytest.mark.parametrize('pose', [(2.31, -0.05, 0.03), (2.0, 0.01, -0.2), (0.5, 0.0, 0.0)])
def test_tip_pose_round_trip(pose):
    assert tip_pose_from_transform(tip_transform(*pose)) == pytest.approx(pose, abs=1e-12)


def test_inverse_and_compose():
    a = Transform.from_xyz_rpy((0.1, -0.2, 0.3), (0.3, -0.2, 1.0))
    identity = a @ a.inverse()
    np.testing.assert_allclose(identity.rotation, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(identity.translation, 0.0, atol=1e-12)
    points = np.array([[1.0, 2.0, 3.0], [-1.0, 0.5, 0.0]])
    np.testing.assert_allclose(a.inverse().apply(a.apply(points)), points, atol=1e-12)


def test_pitch_quaternion_is_a_rotation_about_y():
    x, y, z, w = pitch_quaternion(0.4)
    assert (x, z) == (0.0, 0.0)
    assert 2 * np.arctan2(y, w) == pytest.approx(0.4)
