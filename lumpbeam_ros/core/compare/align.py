"""Aligning a reference stream to the camera in time and space, from the data alone.

The steps: check that the stamps can overlap and that the reference points can fix a
rotation; find the coarse offset by cross-correlation (:mod:`~.offset`); fit the rigid
transform by Kabsch on the time-aligned samples (:mod:`~.rigid`); refine offset and
transform together by least squares (:mod:`~.refine`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.compare.offset import CoarseOffset, check_overlap, coarse_offset
from lumpbeam_ros.core.compare.refine import MIN_PAIRS, Alignment, refine_alignment
from lumpbeam_ros.core.compare.rigid import (
    MIN_MOTION_M,
    check_rotation_observable,
    fit_rigid,
    point_spread,
)
from lumpbeam_ros.core.compare.streams import GapInterpolator, Track


@dataclass(frozen=True)
class AlignOptions:
    """How the alignment searches.

    Attributes:
        max_offset_s: Largest ``|offset|`` between the clocks searched, s.
        max_gap_s: Longest reference dropout still bridged by interpolation, s (default
            2.5 median reference periods).
        margin_periods: Distance kept from reference gaps and ends, in reference periods.
    """

    max_offset_s: float = 1.0
    max_gap_s: float | None = None
    margin_periods: float = 2.0

    def __post_init__(self) -> None:
        if not self.max_offset_s > 0.0:
            raise LumpbeamError(f'max offset must be positive, got {self.max_offset_s}')
        if self.max_gap_s is not None and not self.max_gap_s > 0.0:
            raise LumpbeamError(f'max gap must be positive, got {self.max_gap_s}')


@dataclass(frozen=True)
class AlignedStreams:
    """The alignment with what it was computed from.

    Attributes:
        alignment: Offset and transform, refined.
        coarse: The cross-correlation estimate it started from.
        reference: The reference stream, interpolated (its gaps are ``reference.gap_count``).
    """

    alignment: Alignment
    coarse: CoarseOffset
    reference: GapInterpolator


def align_streams(
    camera: Track, reference: Track, options: AlignOptions | None = None
) -> AlignedStreams:
    """Finds the clock offset and the transform from the reference frame to ``beam_base``.

    Args:
        camera: Camera tip positions in ``beam_base`` (``y = 0``).
        reference: Reference-sensor positions in its own frame and clock.
        options: Search settings.

    Returns:
        The alignment.

    Raises:
        LumpbeamError: The stamps never overlap, either stream does not move, the reference
            moves on a line only (rotation unobservable), or the motions do not match.
    """
    options = options or AlignOptions()
    check_overlap(camera, reference, options.max_offset_s)
    camera_motion = float(np.std(camera.points[:, 2]))
    if camera_motion < MIN_MOTION_M:
        raise LumpbeamError(
            f'{camera.source}: the tip does not move ({camera_motion * 1e6:.3g} um RMS in z): '
            'nothing to compare'
        )
    spread = point_spread(reference.points)
    check_rotation_observable(spread, reference.source)
    interpolator = GapInterpolator(reference, options.max_gap_s)
    coarse = coarse_offset(camera, interpolator, spread, options.max_offset_s)
    margin = options.margin_periods * reference.period_s
    pairs = interpolator.valid(camera.t + coarse.offset_s, margin)
    if np.count_nonzero(pairs) < MIN_PAIRS:
        raise LumpbeamError(
            f'{camera.source} and {reference.source} overlap at only '
            f'{np.count_nonzero(pairs)} camera samples once aligned in time'
        )
    initial = fit_rigid(interpolator(camera.t[pairs] + coarse.offset_s), camera.points[pairs])
    alignment = refine_alignment(camera, interpolator, coarse.offset_s, initial, margin)
    return AlignedStreams(alignment, coarse, interpolator)
