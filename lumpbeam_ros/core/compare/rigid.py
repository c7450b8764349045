"""The least-squares fit of a rigid transform between sensor frames, and its observability.

A tracker that follows the tip sees it move on a curve in one plane (the ``x``-``z`` plane
of ``beam_base``): mostly up and down, with a small bow along the beam from foreshortening.
Whether that cloud pins down a rotation is checked by :func:`point_spread` before any fit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.compare.transforms import RigidTransform

#: Least motion along the main direction, m (RMS about the mean): below it nothing moves.
MIN_MOTION_M = 1e-4

#: Least ratio of the second to the third spread: below it the points lie on a line.
MIN_PLANARITY = 2.0


@dataclass(frozen=True)
class Spread:
    """Principal spreads of a point cloud.

    Attributes:
        rms_m: RMS distance from the mean along each principal direction, descending.
        directions: The principal directions as rows, ``(3, 3)``.
        mean: The centroid, ``(3,)``.
    """

    rms_m: np.ndarray
    directions: np.ndarray
    mean: np.ndarray


def point_spread(points: np.ndarray) -> Spread:
    """Principal component analysis of ``(n, 3)`` points."""
    mean = points.mean(axis=0)
    _, singular, directions = np.linalg.svd(points - mean, full_matrices=False)
    return Spread(singular / math.sqrt(points.shape[0]), directions, mean)


def check_rotation_observable(spread: Spread, source: str) -> None:
    """Raises unless the points move enough, and off a line, to fix a rotation.

    Three points on a line leave the rotation about that line free; a rotation is fixed
    only if the cloud is clearly wider in a second direction than the noise in the third.

    Args:
        spread: The reference points' spread (:func:`point_spread`).
        source: The stream's name, for the message.

    Raises:
        LumpbeamError: The points do not move, or they move along a line only.
    """
    first, second, third = spread.rms_m
    if first < MIN_MOTION_M or first < 5.0 * third:
        raise LumpbeamError(
            f'{source}: the points do not move ({first * 1e3:.3g} mm RMS along their main '
            'direction): cannot align the frames'
        )
    if second < MIN_PLANARITY * third:
        raise LumpbeamError(
            f'{source}: the points lie on a line ({second * 1e6:.3g} um across it against '
            f'{third * 1e6:.3g} um of noise): the rotation about it is unobservable'
        )


def fit_rigid(source: np.ndarray, target: np.ndarray) -> RigidTransform:
    """Least-squares rigid transform ``target ~ R source + t`` (Kabsch / Umeyama, no scale).

    Args:
        source: ``(n, 3)`` points.
        target: ``(n, 3)`` corresponding points.

    Returns:
        The transform; the sign correction keeps ``det R = +1`` (no reflection), which also
        makes the fit unique for a planar, non-collinear cloud.
    """
    source_mean, target_mean = source.mean(axis=0), target.mean(axis=0)
    cross = (target - target_mean).T @ (source - source_mean)
    u, _, vt = np.linalg.svd(cross)
    sign = np.diag([1.0, 1.0, np.sign(np.linalg.det(u @ vt)) or 1.0])
    rotation = u @ sign @ vt
    return RigidTransform(rotation, target_mean - rotation @ source_mean)


def skew(v: np.ndarray) -> np.ndarray:
    """Cross-product matrices ``[v]x`` of ``(n, 3)`` vectors, ``(n, 3, 3)``."""
    out = np.zeros((*v.shape[:-1], 3, 3))
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out
