"""Tip pose from checkerboard corners: the plane-constrained fit and free PnP.

The tip moves in the bending plane, so once the camera mount and the board pose are fixed,
the corners' image positions depend on three numbers only: the tip's ``x``, ``z`` and
``pitch``. Fitting those three to all corners is far better conditioned than a 6-DoF PnP,
whose depth and out-of-plane tilt trade off against the in-plane translation frame by frame.
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from lumpbeam_ros.core.vision.camera_model import CameraInfo
from lumpbeam_ros.core.vision.config import RigGeometry
from lumpbeam_ros.core.vision.geometry import Transform, tip_pose_from_transform, tip_transform
from lumpbeam_ros.core.vision.reprojection import PoseFit, fit_pose

#: Gauss-Newton stops after a step below this, m or rad. The tip moves parallel to the image
#: plane (constant depth) and the pitch turns the image about the optical axis, so the
#: model's curvature is about 1 per m or rad and the step after one of 0.5 mm is some 0.2 um:
#: on the 2048 x 2048 drop test (bench) the poses moved by at most 0.2 um in x, 0.004 um in
#: z and 0.006 urad in pitch against a 10 um stop, with one step per frame instead of two.
#: The linearized residual and the last Jacobian serve for the covariance.
_STEP_TOLERANCE = 5e-4


class PlaneModel:
    """Projects the board's corners for an in-plane tip pose, with the Jacobian.

    Attributes:
        step_tolerance: Gauss-Newton's stop (:data:`_STEP_TOLERANCE`), m or rad.
        max_iterations: Gauss-Newton iterations at most.

    Args:
        rig: Camera mount and board pose.
        camera_info: Intrinsics; only the pinhole part is used (measured corners are
            undistorted before they are fitted).
    """

    step_tolerance = _STEP_TOLERANCE
    max_iterations = 10

    def __init__(self, rig: RigGeometry, camera_info: CameraInfo):
        self.rig = rig
        self._points = rig.base_board.apply(rig.board.object_points())
        cam_tip = rig.tip_camera.inverse()
        self._r_ct = cam_tip.rotation
        self._t_ct = cam_tip.translation
        # The points' y (across the bending plane) is untouched by the tip's motion.
        self._offset_ct = np.outer(self._points[:, 1], self._r_ct[:, 1]) + self._t_ct
        # Their (x, z) in beam_base, and the camera-frame images of the tip frame's x and z
        # axes (rows): the whole projection is then one N x 2 by 2 x 6 product per step.
        self._points_xz = self._points[:, [0, 2]].copy()
        self._axes_xz = np.array([self._r_ct[:, 0], self._r_ct[:, 2]])
        self._f = np.diag(camera_info.k)[:2].copy()
        self._c = camera_info.k[:2, 2].copy()

    @property
    def n_points(self) -> int:
        """Number of board corners."""
        return int(self._points.shape[0])

    def camera_points(self, pose: np.ndarray) -> np.ndarray:
        """Returns the corners in the camera frame (N x 3) for a tip pose ``(x, z, pitch)``."""
        x, z, pitch = pose
        c, s = np.cos(pitch), np.sin(pitch)
        d = self._points - np.array([x, 0.0, z])
        # R_y(pitch)^T applied to the offsets from the tip, written out for speed.
        tip = np.column_stack([c * d[:, 0] - s * d[:, 2], d[:, 1], s * d[:, 0] + c * d[:, 2]])
        return np.asarray(tip @ self._r_ct.T + self._t_ct)

    def project(self, pose: np.ndarray) -> np.ndarray:
        """Returns the ideal (undistorted) pixel positions of the corners (N x 2)."""
        p = self.camera_points(pose)
        return np.asarray(p[:, :2] / p[:, 2:3] * self._f + self._c)

    def project_with_jacobian(self, pose: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Returns the projected corners (N x 2) and d(pixels)/d(pose) (N x 2 x 3)."""
        x, z, pitch = pose
        c, s = math.cos(pitch), math.sin(pitch)
        # With d = (x_i - x, z_i - z) a corner's offset from the tip in the bending plane, the
        # camera-frame point is d0 m0 + d2 m1 + offset, where m0, m1 are the tip frame's x and
        # z axes turned by the pitch, and its pitch derivative is d0 m1 - d2 m0. This runs in
        # every Gauss-Newton step of every frame, so both come from one product.
        turned = np.array([[c, s], [-s, c]]) @ self._axes_xz  # rows m0, m1
        coefficients = np.empty((2, 6))
        coefficients[:, :3] = turned
        coefficients[0, 3:] = turned[1]
        coefficients[1, 3:] = -turned[0]
        both = (self._points_xz - (x, z)) @ coefficients
        p = both[:, :3] + self._offset_ct
        # Camera-frame derivatives (N x 3 coordinates x 3 parameters): x and z move every
        # corner by -m0 and -m1.
        d_p = np.empty((p.shape[0], 3, 3))
        d_p[:, :, 0] = -turned[0]
        d_p[:, :, 1] = -turned[1]
        d_p[:, :, 2] = both[:, 3:]
        inv_z = 1.0 / p[:, 2]
        uv = p[:, :2] * inv_z[:, None]
        jac = d_p[:, :2, :] - uv[:, :, None] * d_p[:, 2:3, :]
        jac *= inv_z[:, None, None] * self._f[None, :, None]
        return uv * self._f + self._c, jac

    def fit(self, pixels: np.ndarray, initial: np.ndarray) -> PoseFit:
        """Fits ``(x, z, pitch)`` to measured corners (:func:`~.reprojection.fit_pose`).

        Args:
            pixels: Undistorted corner positions (N x 2), in the board's corner order; NaN
                rows (corners not seen: a partial view) are left out.
            initial: Starting pose ``(x, z, pitch)``.

        Returns:
            The fitted pose with its covariance.
        """
        return fit_pose(self, pixels, initial)


def solve_board_pnp(
    object_points: np.ndarray,
    pixels: np.ndarray,
    camera_info: CameraInfo,
    expected_rotation: np.ndarray,
) -> Transform | None:
    """Free 6-DoF board pose by IPPE, refined by Levenberg-Marquardt.

    IPPE returns the two poses a planar target is ambiguous between; the one behind the
    camera or seen from the back is dropped, and when both explain the corners about equally
    the one nearer the expected orientation wins, so a flipped solution never comes out.

    Args:
        object_points: Board corners in the board frame (N x 3).
        pixels: Undistorted corner pixels (N x 2).
        camera_info: Intrinsics (pinhole part used).
        expected_rotation: Roughly expected ``R_camera_board`` (from the configured rig).

    Returns:
        ``T_camera_board``, or ``None`` when no valid solution exists.
    """
    obj = np.ascontiguousarray(object_points, dtype=np.float64)
    img = np.ascontiguousarray(pixels, dtype=np.float64).reshape(-1, 1, 2)
    try:
        n, rvecs, tvecs, errors = cv2.solvePnPGeneric(
            obj, img, camera_info.k, None, flags=cv2.SOLVEPNP_IPPE
        )
    except cv2.error:
        return None
    candidates = []
    for i in range(n):
        rotation = cv2.Rodrigues(rvecs[i])[0]
        t = tvecs[i].ravel()
        # The board's +z points into the wall, away from the camera.
        if t[2] <= 0 or rotation[:, 2] @ t <= 0:
            continue
        error = float(np.ravel(errors)[i])
        angle = np.arccos(np.clip((np.trace(expected_rotation.T @ rotation) - 1) / 2, -1, 1))
        candidates.append((error, angle, rvecs[i], tvecs[i]))
    if not candidates:
        return None
    candidates.sort(key=lambda item: item[0])
    best = candidates[0]
    if len(candidates) > 1 and candidates[1][0] < 1.5 * best[0] + 1e-3:
        # Ambiguous: the errors do not decide, the orientation does.
        best = min(candidates, key=lambda item: item[1])
    rvec, tvec = cv2.solvePnPRefineLM(obj, img, camera_info.k, None, best[2], best[3])
    if not (np.all(np.isfinite(rvec)) and np.all(np.isfinite(tvec))):
        return None
    rotation, t = cv2.Rodrigues(rvec)[0], tvec.ravel()
    # The refinement must not have wandered behind the camera or to the board's back.
    if t[2] <= 0 or rotation[:, 2] @ t <= 0:
        return None
    return Transform(rotation, t)


def tip_pose_from_board_pose(rig: RigGeometry, camera_board: Transform) -> np.ndarray:
    """Converts a 6-DoF board pose in the camera into an in-plane tip pose.

    Args:
        rig: Camera mount and board pose.
        camera_board: ``T_camera_board``.

    Returns:
        ``(x, z, pitch)`` of the tip.
    """
    base_tip = rig.base_board @ camera_board.inverse() @ rig.tip_camera.inverse()
    return np.array(tip_pose_from_transform(base_tip))


def camera_board_transform(rig: RigGeometry, pose: np.ndarray) -> Transform:
    """Returns ``T_camera_board`` for a tip pose ``(x, z, pitch)``."""
    base_tip = tip_transform(*pose)
    return rig.tip_camera.inverse() @ base_tip.inverse() @ rig.base_board
