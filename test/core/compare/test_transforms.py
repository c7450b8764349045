import math

import numpy as np
import pytest

from lumpbeam_ros.core.compare.transforms import RigidTransform
from lumpbeam_ros.core.vision.geometry import rotation_rpy

ANGLES_DEG = [(0.0, 0.0, 0.0), (90.0, 0.0, 0.0), (10.0, -20.0, 30.0), (-170.0, 45.0, 179.0)]


def _quaternion_rotate(q_xyzw: np.ndarray, v: np.ndarray) -> np.ndarray:
    # v' = q v q*, written out with the Hamilton product: independent of any library.
    x, y, z, w = q_xyzw
    u = np.array([x, y, z])
    return 2.0 * u.dot(v) * u + (w * w - u.dot(u)) * v + 2.0 * w * np.cross(u, v)


@pytest.mark.parametrize('angles_deg', ANGLES_DEG)
def test_euler_angles_are_extrinsic_xyz_as_in_urdf(angles_deg):
    transform = RigidTransform.from_euler_deg(angles_deg, (0.1, -0.2, 0.3))
    roll, pitch, yaw = (math.radians(a) for a in angles_deg)
    # Extrinsic x-y-z is Rz(yaw) Ry(pitch) Rx(roll): the rig's own convention (REP-103).
    np.testing.assert_allclose(transform.rotation, rotation_rpy(roll, pitch, yaw), atol=1e-12)
    np.testing.assert_allclose(transform.rotation @ transform.rotation.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(transform.rotation) == pytest.approx(1.0)


@pytest.mark.parametrize('angles_deg', ANGLES_DEG)
def test_inverse_undoes_apply(angles_deg):
    transform = RigidTransform.from_euler_deg(angles_deg, (0.5, 0.0, -1.0))
    points = np.random.default_rng(3).normal(size=(20, 3))
    np.testing.assert_allclose(transform.inverse().apply(transform.apply(points)), points)
    # One point maps as a row of many.
    np.testing.assert_allclose(transform.apply(points[0]), transform.apply(points)[0])
    # Distances are kept.
    moved = transform.apply(points)
    np.testing.assert_allclose(
        np.linalg.norm(moved[1:] - moved[0], axis=1),
        np.linalg.norm(points[1:] - points[0], axis=1),
    )


@pytest.mark.parametrize('angles_deg', ANGLES_DEG)
def test_quaternion_is_the_rotation_with_nonnegative_w(angles_deg):
    transform = RigidTransform.from_euler_deg(angles_deg, (0.0, 0.0, 0.0))
    q = transform.quaternion_xyzw()
    assert q[3] >= 0.0
    assert np.linalg.norm(q) == pytest.approx(1.0)
    for v in np.eye(3):
        np.testing.assert_allclose(_quaternion_rotate(q, v), transform.rotation @ v, atol=1e-12)


@pytest.mark.parametrize(('a_deg', 'b_deg'), [(0.0, 0.0), (10.0, 40.0), (-60.0, 60.0)])
def test_angle_between_rotations_about_one_axis(a_deg, b_deg):
    a = RigidTransform.from_euler_deg((0.0, 0.0, a_deg), (0.0, 0.0, 0.0))
    b = RigidTransform.from_euler_deg((0.0, 0.0, b_deg), (1.0, 2.0, 3.0))
    assert a.angle_to(b) == pytest.approx(math.radians(abs(a_deg - b_deg)), abs=1e-9)
