"""The coarse clock offset between camera and reference, by cross-correlation.

Before the frames are aligned, the only motion the two streams share for sure is the
dominant one: the tip going up and down. The reference's first principal component is
correlated with the camera's ``z`` over a range of lags (the sign of the component is
unknown, so the largest absolute correlation wins), and the peak is refined by a parabola
through its three neighbours. A load release makes the peak unique; a pure free decay leaves
a twin every period, so ``max_offset_s`` should then stay under half a period.

Sign convention (everywhere in :mod:`lumpbeam_ros.core.compare`): ``tracker_stamp =
camera_stamp + offset`` for the same instant.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.compare.rigid import Spread
from lumpbeam_ros.core.compare.streams import GapInterpolator, Track

#: Lowest peak correlation accepted as the same motion seen twice.
MIN_CORRELATION = 0.5

#: Most lags tried; a wide search on a fast reference is sampled more coarsely.
MAX_LAGS = 4001

#: Fewest camera samples that must meet the reference at a lag for it to count.
MIN_PAIRS = 20

#: Lag-sample pairs interpolated per vectorized batch (bounds the memory used).
_BATCH_VALUES = 1_000_000


@dataclass(frozen=True)
class CoarseOffset:
    """The cross-correlation estimate.

    Attributes:
        offset_s: ``tracker_stamp - camera_stamp``, s, to a fraction of a lag step.
        correlation: Peak correlation, signed: negative when the reference's first
            principal direction points down in ``beam_base``.
        lag_step_s: Spacing of the lags tried, s.
    """

    offset_s: float
    correlation: float
    lag_step_s: float


def check_overlap(camera: Track, reference: Track, max_offset_s: float) -> None:
    """Raises unless the stamps can overlap for some offset within ``+- max_offset_s``.

    Raises:
        LumpbeamError: The time ranges are disjoint even after the largest allowed shift.
    """
    (c0, c1), (r0, r1) = camera.span, reference.span
    if r0 - max_offset_s >= c1 or r1 + max_offset_s <= c0:
        raise LumpbeamError(
            f'{camera.source} ({c0:.3f}..{c1:.3f} s) and {reference.source} '
            f'({r0:.3f}..{r1:.3f} s) never overlap in time, even shifted by up to '
            f'{max_offset_s:g} s (the clocks must agree to within --max-offset)'
        )


def coarse_offset(
    camera: Track,
    reference: GapInterpolator,
    spread: Spread,
    max_offset_s: float,
) -> CoarseOffset:
    """Finds the lag at which the reference's main motion best matches the camera's ``z``.

    Args:
        camera: Camera positions in ``beam_base``.
        reference: The reference stream, interpolated.
        spread: The reference points' principal directions (:func:`~.rigid.point_spread`).
        max_offset_s: Largest ``|offset|`` searched, s.

    Returns:
        The offset estimate.

    Raises:
        LumpbeamError: No lag gives :data:`MIN_PAIRS` overlapping samples, or the best
            correlation is below :data:`MIN_CORRELATION`.
    """
    step = max(reference.track.period_s, 2.0 * max_offset_s / (MAX_LAGS - 1))
    half = int(np.ceil(max_offset_s / step))
    lags = np.arange(-half, half + 1) * step
    signal = (reference.track.points - spread.mean) @ spread.directions[0]
    z = camera.points[:, 2]
    correlation = np.full(lags.size, np.nan)
    batch_lags = max(1, _BATCH_VALUES // len(camera))
    for lo in range(0, lags.size, batch_lags):
        batch = lags[lo : lo + batch_lags, None]
        query = camera.t[None, :] + batch
        mask = reference.valid(query)
        values = reference.scalar(signal, query)
        correlation[lo : lo + batch_lags] = _masked_correlation(z, values, mask)
    if not np.any(np.isfinite(correlation)):
        raise LumpbeamError(
            f'{camera.source} and {reference.track.source} share fewer than {MIN_PAIRS} '
            f'samples at every offset within +-{max_offset_s:g} s: they never overlap in time'
        )
    strength = np.nan_to_num(np.abs(correlation), nan=-1.0)
    best = int(np.argmax(strength))
    if strength[best] < MIN_CORRELATION:
        raise LumpbeamError(
            f'{camera.source} and {reference.track.source} do not move together: best '
            f'correlation {strength[best]:.2f} (need {MIN_CORRELATION}) within '
            f'+-{max_offset_s:g} s'
        )
    offset = lags[best] + step * _parabola_vertex(strength, best)
    return CoarseOffset(float(offset), float(correlation[best]), float(step))


def _masked_correlation(z: np.ndarray, values: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """Pearson correlation of ``z`` with each row of ``values`` over the row's ``mask``."""
    weights = mask.astype(float)
    count = weights.sum(axis=1)
    safe = np.maximum(count, 1.0)
    mean_z = (weights * z).sum(axis=1) / safe
    mean_v = (weights * values).sum(axis=1) / safe
    dz = (z[None, :] - mean_z[:, None]) * weights
    dv = (values - mean_v[:, None]) * weights
    denominator = np.sqrt((dz * dz).sum(axis=1) * (dv * dv).sum(axis=1))
    with np.errstate(invalid='ignore', divide='ignore'):
        out: np.ndarray = (dz * dv).sum(axis=1) / denominator
    out[(count < MIN_PAIRS) | ~(denominator > 0.0)] = np.nan
    return out


def _parabola_vertex(values: np.ndarray, index: int) -> float:
    """Sub-step position (-0.5..0.5) of the vertex of the parabola through a peak."""
    if index == 0 or index == values.size - 1:
        return 0.0
    left, centre, right = values[index - 1 : index + 2]
    curvature = left - 2.0 * centre + right
    if not curvature < 0.0:
        return 0.0
    return float(np.clip(0.5 * (left - right) / curvature, -0.5, 0.5))
