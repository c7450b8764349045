"""Estimating the rig's fixed unknowns once, from many frames.

The tip moves in the bending plane, which the board is parallel to, so three things never
change between frames: the camera's distance to the board and the two angles by which its
optical axis tilts out of the plane. They are common to every frame, so a joint fit of them
and of every frame's ``(x, z, pitch)`` over many frames estimates them; afterwards each frame
needs only the well-conditioned 3-DoF fit.

The depth is well determined (the board's known squares give the scale). The tilts are not:
a tilt by ``a`` shifts the whole image like a tip translation by ``a`` times the distance,
and only the faint keystone it adds (about 0.1 px per mrad at the board's edge at 1024 px)
tells them apart. Over 30 frames with 0.05 px corner noise that leaves some 60 urad of
uncertainty, 57 um of tip bias at 0.95 m, and corner biases of a few thousandths of a pixel
(an illumination gradient across the corner windows) pull it by tens of urad more: the
validation matrix saw 15 um of z bias from a 20 urad prior at 2048 px. So the tilts enter
with a tight Gaussian prior around the configured mount (``tilt_prior_std_rad``): the
images do not pull a well measured mount off by their own noise (and cannot correct a badly
measured one much either: measure it).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import least_squares
from scipy.sparse import lil_matrix

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.vision.camera_model import CameraInfo
from lumpbeam_ros.core.vision.config import RigGeometry
from lumpbeam_ros.core.vision.geometry import Transform, rotation_x, rotation_z
from lumpbeam_ros.core.vision.pose import PlaneModel


@dataclass(frozen=True)
class RigCalibration:
    """The refined rig and what was changed.

    Attributes:
        rig: The rig with the camera's tilt and the board's distance corrected.
        tilt_rad: Added rotation of the camera mount about the tip's x and z axes, rad.
        depth_offset_m: Added offset of the board along ``beam_base`` y, m.
        std: Standard deviations of ``(tilt_x, tilt_z, depth_offset)``.
        rms_px: RMS reprojection error per corner over all frames, px.
        frames: Frames used.
    """

    rig: RigGeometry
    tilt_rad: tuple[float, float]
    depth_offset_m: float
    std: np.ndarray
    rms_px: float
    frames: int


def adjusted_rig(rig: RigGeometry, tilt_x: float, tilt_z: float, depth: float) -> RigGeometry:
    """Returns ``rig`` with the camera tilted about the tip's x, z axes and the board moved.

    Args:
        rig: The configured rig.
        tilt_x: Extra camera rotation about the tip's x axis, rad.
        tilt_z: Extra camera rotation about the tip's z axis, rad.
        depth: Extra board offset along ``beam_base`` y, m.

    Returns:
        The adjusted rig.
    """
    mount = rig.tip_camera
    turned = Transform(rotation_x(tilt_x) @ rotation_z(tilt_z) @ mount.rotation, mount.translation)
    board = Transform(
        rig.base_board.rotation, rig.base_board.translation + np.array([0.0, depth, 0.0])
    )
    return replace(rig, tip_camera=turned, base_board=board)


def calibrate_rig(
    rig: RigGeometry,
    camera_info: CameraInfo,
    pixels: Sequence[np.ndarray],
    poses: Sequence[np.ndarray],
    tilt_prior_std_rad: float | None = None,
) -> RigCalibration:
    """Jointly fits the fixed unknowns and every frame's in-plane pose.

    Args:
        rig: The configured rig (the starting point and the gauge: in-plane offsets of the
            camera and the board stay as configured).
        camera_info: Intrinsics.
        pixels: Per frame, the undistorted corners (N x 2).
        poses: Per frame, a starting ``(x, z, pitch)``.
        tilt_prior_std_rad: How well the configured mount's tilt is known, rad; the
            tilts are fitted with this Gaussian prior around zero (``None``: no prior).

    Returns:
        The calibration.

    Raises:
        LumpbeamError: Too few frames (three without a tilt prior, one with it), or the
            fit fails.
    """
    n_frames = len(pixels)
    # With a tilt prior one frame determines the depth (the board's scale); free tilts need
    # several views.
    least = 1 if tilt_prior_std_rad is not None else 3
    if n_frames < least or len(poses) != n_frames:
        raise LumpbeamError(f'calibration: need at least {least} frames, each with a start pose')
    measured = np.stack([np.asarray(p, dtype=float) for p in pixels])
    n_points = measured.shape[1]

    start = np.concatenate([np.zeros(3), np.asarray(poses, dtype=float).ravel()])
    prior_weight = 0.0

    def residuals(params: np.ndarray) -> np.ndarray:
        model = PlaneModel(adjusted_rig(rig, *params[:3]), camera_info)
        frame_poses = params[3:].reshape(n_frames, 3)
        return np.concatenate(
            [(model.project(q) - m).ravel() for q, m in zip(frame_poses, measured, strict=True)]
            + [prior_weight * params[:2]]
        )

    if tilt_prior_std_rad is not None:
        # The per-frame fits the start poses come from leave about the corner noise:
        # a tilt of one prior sigma then weighs like one corner's noise.
        noise_px = float(np.sqrt(np.mean(residuals(start)[:-2] ** 2)))
        prior_weight = max(noise_px, 1e-3) / tilt_prior_std_rad
    sparsity = lil_matrix((n_frames * n_points * 2 + 2, 3 + 3 * n_frames), dtype=int)
    for k in range(n_frames):
        rows = slice(k * n_points * 2, (k + 1) * n_points * 2)
        sparsity[rows, :3] = 1
        sparsity[rows, 3 + 3 * k : 6 + 3 * k] = 1
    sparsity[-2, 0] = sparsity[-1, 1] = 1
    # Steps of 1e-7 (rad, m) resolve micrometre effects without drowning in round-off.
    fit = least_squares(
        residuals, start, jac_sparsity=sparsity, method='trf', x_scale='jac', diff_step=1e-7
    )
    if not fit.success or not np.all(np.isfinite(fit.x)):
        raise LumpbeamError(f'calibration: the fit failed ({fit.message})')
    j = fit.jac.toarray() if hasattr(fit.jac, 'toarray') else fit.jac
    dof = max(fit.fun.size - 2 - fit.x.size, 1)
    sigma2 = float(fit.fun[:-2] @ fit.fun[:-2]) / dof
    try:
        std = np.sqrt(np.diag(np.linalg.inv(j.T @ j))[:3] * sigma2)
    except np.linalg.LinAlgError:
        std = np.full(3, np.inf)
    tilt_x, tilt_z, depth = (float(v) for v in fit.x[:3])
    return RigCalibration(
        rig=adjusted_rig(rig, tilt_x, tilt_z, depth),
        tilt_rad=(tilt_x, tilt_z),
        depth_offset_m=depth,
        std=std,
        rms_px=float(np.sqrt(np.mean(fit.fun[:-2].reshape(-1, 2) ** 2) * 2)),
        frames=n_frames,
    )
