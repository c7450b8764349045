"""The free 6-DoF pose model: the tip anywhere, turned any way.

For footage where the plane-of-bending assumption does not hold (torsion, a handheld
check), the tip's full pose ``(x, y, z, roll, pitch, yaw)`` in ``beam_base`` is fitted to
the corners by Gauss-Newton on the reprojection error, with the covariance
``sigma^2 (J^T J)^-1`` in the order of ``geometry_msgs/PoseWithCovariance`` (x, y, z, then
rotations about x, y, z as roll, pitch, yaw: REP-103's fixed-axis ``Rz Ry Rx``). With
identity camera mount and board pose in the configuration, the tip frame is the camera's
optical frame and ``beam_base`` is the board's, so the pose is the camera's in the board's
frame.

A flat board leaves the out-of-plane parts (depth along the optical axis, tilt) much less
certain than the plane-constrained fit's three numbers; the covariance says by how much.
"""

from __future__ import annotations

import numpy as np

from lumpbeam_ros.core.vision.camera_model import CameraInfo
from lumpbeam_ros.core.vision.config import RigGeometry
from lumpbeam_ros.core.vision.geometry import Transform, rotation_rpy
from lumpbeam_ros.core.vision.reprojection import PoseFit, fit_pose

#: The pose models a tracker fits: ``plane`` (x, z, pitch in the plane of bending) or
#: ``free`` (the full 6-DoF pose).
POSE_MODELS = ('plane', 'free')

# Central-difference steps for the Jacobian, m and rad: at ~1 m and 1e-6 the truncation
# error (~1e-12 relative) and round-off (~1e-10 relative) are both far below the noise.
_STEP = 1e-6


def rpy_from_rotation(rotation: np.ndarray) -> np.ndarray:
    """Roll, pitch, yaw of a rotation ``Rz(yaw) Ry(pitch) Rx(roll)`` (inverse of ``rotation_rpy``).

    Args:
        rotation: 3x3 rotation matrix.

    Returns:
        ``(roll, pitch, yaw)``, rad; pitch in [-pi/2, pi/2].
    """
    r = rotation
    pitch = np.arctan2(-r[2, 0], np.hypot(r[0, 0], r[1, 0]))
    return np.array([np.arctan2(r[2, 1], r[2, 2]), pitch, np.arctan2(r[1, 0], r[0, 0])])


def rpy_quaternion(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    """The quaternion ``(x, y, z, w)`` of ``Rz(yaw) Ry(pitch) Rx(roll)``.

    Args:
        roll: rad.
        pitch: rad.
        yaw: rad.

    Returns:
        The unit quaternion in the order of ``geometry_msgs/Quaternion``.
    """
    cr, sr = np.cos(roll / 2), np.sin(roll / 2)
    cp, sp = np.cos(pitch / 2), np.sin(pitch / 2)
    cy, sy = np.cos(yaw / 2), np.sin(yaw / 2)
    return (
        float(sr * cp * cy - cr * sp * sy),
        float(cr * sp * cy + sr * cp * sy),
        float(cr * cp * sy - sr * sp * cy),
        float(cr * cp * cy + sr * sp * sy),
    )


def planar_part(pose: np.ndarray, covariance: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The in-plane ``(x, z, pitch)`` of a 6-DoF pose and its 3x3 covariance.

    The pitch is the slope of the tip's rotated x axis, ``atan2(-R_zx, R_xx)``: what a
    reader of the published quaternion recovers as the pitch (equal to the Euler pitch when
    yaw is zero; the covariance's pitch row is the Euler pitch's, equal to first order).

    Args:
        pose: ``(x, y, z, roll, pitch, yaw)``.
        covariance: Its 6x6 covariance.

    Returns:
        ``(x, z, pitch)`` and its covariance.
    """
    r = rotation_rpy(*pose[3:])
    planar = np.array([pose[0], pose[2], np.arctan2(-r[2, 0], r[0, 0])])
    index = np.array([0, 2, 4])
    return planar, covariance[np.ix_(index, index)].copy()


class FreeModel:
    """Projects the board's corners for a 6-DoF tip pose.

    Args:
        rig: Camera mount and board pose.
        camera_info: Intrinsics; only the pinhole part is used (measured corners are
            undistorted before they are fitted).
    """

    #: Gauss-Newton converges quadratically: a 1e-9 step (m, rad) leaves nothing measurable.
    step_tolerance = 1e-9
    max_iterations = 20

    def __init__(self, rig: RigGeometry, camera_info: CameraInfo):
        self.rig = rig
        self._points = rig.base_board.apply(rig.board.object_points())
        self._camera_tip = rig.tip_camera.inverse()
        self._f = np.diag(camera_info.k)[:2].copy()
        self._c = camera_info.k[:2, 2].copy()

    def camera_points(self, pose: np.ndarray) -> np.ndarray:
        """Returns the corners in the camera frame (N x 3) for a tip pose (6 numbers)."""
        base_tip = Transform(rotation_rpy(*pose[3:]), np.asarray(pose[:3], dtype=float))
        return (self._camera_tip @ base_tip.inverse()).apply(self._points)

    def project(self, pose: np.ndarray) -> np.ndarray:
        """Returns the ideal (undistorted) pixel positions of the corners (N x 2)."""
        p = self.camera_points(pose)
        return np.asarray(p[:, :2] / p[:, 2:3] * self._f + self._c)

    def jacobian(self, pose: np.ndarray) -> np.ndarray:
        """d(pixels)/d(pose) by central differences (N x 2 x 6)."""
        columns = []
        for i in range(6):
            step = np.zeros(6)
            step[i] = _STEP
            columns.append((self.project(pose + step) - self.project(pose - step)) / (2 * _STEP))
        return np.stack(columns, axis=2)

    def project_with_jacobian(self, pose: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Returns the projected corners (N x 2) and d(pixels)/d(pose) (N x 2 x 6)."""
        return self.project(pose), self.jacobian(pose)

    def fit(self, pixels: np.ndarray, initial: np.ndarray) -> PoseFit:
        """Fits the 6-DoF pose to measured corners (:func:`~.reprojection.fit_pose`).

        Args:
            pixels: Undistorted corner positions (N x 2) in board order; NaN rows (corners
                not seen) are left out.
            initial: Starting pose ``(x, y, z, roll, pitch, yaw)``.

        Returns:
            The fitted pose with its covariance in PoseWithCovariance order; a fit with
            fewer than 4 corners, or a singular one, is not converged.
        """
        return fit_pose(self, pixels, initial)


def free_pose_from_board_pose(rig: RigGeometry, camera_board: Transform) -> np.ndarray:
    """The 6-DoF tip pose that puts the board at ``T_camera_board``.

    Args:
        rig: Camera mount and board pose.
        camera_board: ``T_camera_board`` (e.g. from PnP).

    Returns:
        ``(x, y, z, roll, pitch, yaw)`` of the tip in ``beam_base``.
    """
    base_tip = rig.base_board @ camera_board.inverse() @ rig.tip_camera.inverse()
    return np.concatenate([base_tip.translation, rpy_from_rotation(base_tip.rotation)])
