"""Joint least-squares refinement of the clock offset and the frame transform.

Unknowns: the rotation and translation taking tracker coordinates to ``beam_base`` and the
offset ``tau`` (``tracker_stamp = camera_stamp + tau``). Two blocks of residuals:

* pairs: at each camera stamp ``t_i``, the camera's ``x`` and ``z`` minus those of the
  transformed reference read at ``t_i + tau``. These fix the offset, the translation and the
  rotation about the axes the tip's large vertical motion spans.
* plane: the transformed ``y`` of every reference sample, which is zero because the tip moves
  in the ``x``-``z`` plane (doc/interfaces.md). The rotation about the vertical is seen only
  through the tip's small bow along the beam, so every reference sample counts here, not
  just the ones at camera stamps.

Each block is weighted by the RMS of its own residuals (re-estimated every iteration), so the
covariance ``(J^T J)^-1`` of the weighted problem is in physical units. The rotation is
updated on the left, ``R <- exp([w]x) R``: its standard deviations are about the
``beam_base`` axes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.compare.rigid import skew
from lumpbeam_ros.core.compare.streams import GapInterpolator, Track
from lumpbeam_ros.core.compare.transforms import RigidTransform

#: Fewest camera samples that must meet valid reference samples.
MIN_PAIRS = 20

#: Gauss-Newton stops when no update exceeds this (s, rad, m): far below any noise.
TOLERANCE = 1e-10

MAX_ITERATIONS = 30

#: Largest condition number of the parameters' correlation matrix still called determined.
MAX_CONDITION = 1e12

#: Stretches of the record whose separate offsets test the offset's consistency.
SEGMENTS = 8

#: Floor of the residual RMS used as a weight, m (noise-free synthetic data).
_MIN_RMS = 1e-9


@dataclass(frozen=True)
class Alignment:
    """The refined offset and transform with their standard deviations.

    Attributes:
        offset_s: ``tracker_stamp - camera_stamp`` for the same instant, s.
        offset_std_s: Its standard deviation, s: the white-noise one times
            ``max(1, offset_consistency)``.
        offset_std_white_s: The standard deviation from ``(J^T J)^-1``, which holds for
            white noise only.
        offset_consistency: Birge ratio of the offsets fitted to :data:`SEGMENTS` stretches
            of the record: about 1 when they agree within their own noise, larger when the
            offset wanders (clock drift, stamp jitter, correlated errors).
        transform: Tracker frame to ``beam_base``.
        rotation_std_rad: Standard deviation of the rotation about the ``beam_base`` x, y, z
            axes, rad.
        translation_std_m: Standard deviation of the translation, ``(3,)``, m.
        pairs: Mask of the camera samples that met valid reference samples.
        plane_samples: Reference samples in the plane block.
        pair_rms_m: RMS of the pair residuals (x and z), m.
        plane_rms_m: RMS of the reference's distance from the plane, m.
        iterations: Gauss-Newton iterations taken.
    """

    offset_s: float
    offset_std_s: float
    offset_std_white_s: float
    offset_consistency: float
    transform: RigidTransform
    rotation_std_rad: np.ndarray
    translation_std_m: np.ndarray
    pairs: np.ndarray
    plane_samples: int
    pair_rms_m: float
    plane_rms_m: float
    iterations: int


def refine_alignment(
    camera: Track,
    reference: GapInterpolator,
    offset_s: float,
    transform: RigidTransform,
    margin_s: float,
) -> Alignment:
    """Refines offset and transform jointly by Gauss-Newton from a close start.

    Args:
        camera: Camera positions in ``beam_base`` (``y = 0``).
        reference: The reference stream in its own frame, interpolated.
        offset_s: Starting offset (cross-correlation), s.
        transform: Starting transform (Kabsch fit at that offset).
        margin_s: Distance kept from reference gaps and ends; also the half-width of the
            velocity used for the offset's derivative.

    Returns:
        The alignment.

    Raises:
        LumpbeamError: Fewer than :data:`MIN_PAIRS` camera samples meet the reference, or
            the problem is singular (nothing constrains the offset).
    """
    rotation, translation, tau = transform.rotation, transform.translation.copy(), offset_s
    start, end = camera.span
    in_span = (reference.track.t >= start + offset_s) & (reference.track.t <= end + offset_s)
    plane_points = reference.track.points[in_span]
    iterations = 0
    while iterations < MAX_ITERATIONS:
        iterations += 1
        jacobian, residual, _ = _linearize(
            camera, reference, rotation, translation, tau, plane_points, margin_s
        )
        step = -np.linalg.lstsq(jacobian, residual, rcond=None)[0]
        rotation = Rotation.from_rotvec(step[:3]).as_matrix() @ rotation
        translation = translation + step[3:6]
        tau += float(step[6])
        if np.max(np.abs(step)) < TOLERANCE:
            break
    jacobian, _, (pairs, pair_rms, plane_rms) = _linearize(
        camera, reference, rotation, translation, tau, plane_points, margin_s
    )
    normal = jacobian.T @ jacobian
    # The condition of the correlation matrix: the parameters' units must not decide it.
    scale = np.sqrt(np.diag(normal))
    if np.any(scale == 0.0) or np.linalg.cond(normal / np.outer(scale, scale)) > MAX_CONDITION:
        raise LumpbeamError(
            f'{camera.source} vs {reference.track.source}: the offset and transform are not '
            'determined by the data (no motion where the streams overlap)'
        )
    std = np.sqrt(np.diag(np.linalg.inv(normal)))
    consistency = _offset_consistency(
        camera, reference, RigidTransform(rotation, translation), tau, pairs, margin_s
    )
    return Alignment(
        offset_s=tau,
        offset_std_s=float(std[6]) * max(1.0, consistency),
        offset_std_white_s=float(std[6]),
        offset_consistency=consistency,
        transform=RigidTransform(rotation, translation),
        rotation_std_rad=std[:3],
        translation_std_m=std[3:6],
        pairs=pairs,
        plane_samples=int(plane_points.shape[0]),
        pair_rms_m=pair_rms,
        plane_rms_m=plane_rms,
        iterations=iterations,
    )


def _linearize(
    camera: Track,
    reference: GapInterpolator,
    rotation: np.ndarray,
    translation: np.ndarray,
    tau: float,
    plane_points: np.ndarray,
    margin_s: float,
) -> tuple[np.ndarray, np.ndarray, tuple[np.ndarray, float, float]]:
    """Weighted Jacobian and residuals at the current estimate, with the pair mask and RMS."""
    query = camera.t + tau
    pairs = reference.valid(query, margin_s)
    count = int(np.count_nonzero(pairs))
    if count < MIN_PAIRS:
        raise LumpbeamError(
            f'{camera.source} and {reference.track.source} overlap at only {count} camera '
            f'samples (need {MIN_PAIRS}) once aligned in time'
        )
    moved = reference(query[pairs]) @ rotation.T
    velocity = reference.velocity(query[pairs], margin_s) @ rotation.T
    in_plane = [0, 2]
    pair_res = (camera.points[pairs] - moved - translation)[:, in_plane]
    pair_jac = np.zeros((count, 2, 7))
    pair_jac[:, :, :3] = skew(moved)[:, in_plane, :]
    pair_jac[:, 0, 3] = pair_jac[:, 1, 5] = -1.0
    pair_jac[:, :, 6] = -velocity[:, in_plane]

    plane_moved = plane_points @ rotation.T
    plane_res = -(plane_moved[:, 1] + translation[1])
    plane_jac = np.zeros((plane_points.shape[0], 7))
    plane_jac[:, :3] = skew(plane_moved)[:, 1, :]
    plane_jac[:, 4] = -1.0

    pair_rms = float(np.sqrt(np.mean(pair_res**2)))
    plane_rms = float(np.sqrt(np.mean(plane_res**2))) if plane_res.size else 0.0
    pair_w, plane_w = 1.0 / max(pair_rms, _MIN_RMS), 1.0 / max(plane_rms, _MIN_RMS)
    jacobian = np.vstack([pair_jac.reshape(-1, 7) * pair_w, plane_jac * plane_w])
    residual = np.concatenate([pair_res.ravel() * pair_w, plane_res * plane_w])
    return jacobian, residual, (pairs, pair_rms, plane_rms)


def _offset_consistency(
    camera: Track,
    reference: GapInterpolator,
    transform: RigidTransform,
    tau: float,
    pairs: np.ndarray,
    margin_s: float,
) -> float:
    """Birge ratio ``sqrt(chi^2 / (K - 1))`` of the offsets of :data:`SEGMENTS` stretches.

    Each stretch gets one Gauss-Newton step in the offset alone, from the joint solution
    with the transform held; its variance is the white-noise one, ``s^2 / sum(J^2)``. A
    stretch at rest says nothing about the offset and drops out by its huge variance.
    """
    query = camera.t[pairs] + tau
    moved = transform.apply(reference(query))
    residual = (camera.points[pairs] - moved)[:, [0, 2]]
    slope = -(reference.velocity(query, margin_s) @ transform.rotation.T)[:, [0, 2]]
    noise_var = float(np.mean(residual**2))
    steps, variances = [], []
    for chunk in np.array_split(np.arange(query.size), SEGMENTS):
        information = float(np.sum(slope[chunk] ** 2))
        if chunk.size < MIN_PAIRS or information <= 0.0:
            continue
        steps.append(-float(np.sum(slope[chunk] * residual[chunk])) / information)
        variances.append(noise_var / information)
    if len(steps) < 2:
        return 1.0
    step, weight = np.array(steps), 1.0 / np.array(variances)
    mean = float(np.sum(weight * step) / np.sum(weight))
    chi2 = float(np.sum(weight * (step - mean) ** 2))
    return float(np.sqrt(chi2 / (len(steps) - 1)))
