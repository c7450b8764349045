"""Partial views: which predicted corners are really seen, and whether enough of them are.

While tracking, the last poses predict every corner, including those out of the image or
behind an occluder (a cable, a hand). Each corner whose refinement window lies inside the
image is refined on its own and then has to pass two checks before it joins the fit:

1. **Saddle check** (:func:`saddle_fit`): the pixels of its window, away from the two edge
   lines through it, must look like a checkerboard corner: two grey levels on the two
   diagonals, in the colour order the corner's parity requires, with little else. An
   occluder anywhere in the window (the pixels ``cornerSubPix`` reads) changes some of
   those pixels, so a corner whose refinement it could bias is dropped, not fitted.
2. **Residual check** (:func:`reject_outliers`): a homography through the surviving
   corners (exact for a flat board seen by a pinhole after undistortion, so it needs no
   rig calibration and holds for any pose) must pass every corner within a few times the
   corners' own scatter; the worst one is dropped until all do. This catches what the
   saddle check cannot see: a thin line lying along an edge through the corner.

What is left must clear a documented minimum (:func:`coverage_problem`) so the pose fit
stays well conditioned: at least ``tracker.min_corners`` corners, spread at least
``tracker.min_corner_spread`` squares (rms) across their weakest direction, which a single
row or a diagonal line of corners is not.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import cv2
import numpy as np
from scipy.special import erf

from lumpbeam_ros.core.vision.reprojection import sorted_median

#: Blurs (Gaussian sigma, px) the saddle model tries: defocus from none to 1.5 px, plus the
#: pixel's own footprint and the renderer's or lens's smoothing.
BLURS_PX = (0.6, 0.9, 1.3, 1.8)

#: The blur :func:`select_corners` tries first, px: a sharp image's (pixel footprint and
#: renderer or lens smoothing). Most corners fit it well enough that the others need not
#: be tried; a defocused camera only loses that saving.
FIRST_BLUR_PX = 0.9

#: Largest rms residual of the saddle model, as a fraction of its amplitude: clean corners
#: measure 0.03 to 0.045 (2 DN noise, blur 0.8 to 1.6 px); with a 2 to 8 px bar of any grey
#: level painted at any angle and offset across the window, the corners passing 0.08 were
#: biased by at most 0.11 px (blur 0.8) and 0.18 px (blur 1.6), which the residual check
#: then sees. A noisier or paler frame raises the limit to :data:`MISFIT_MEDIANS` times
#: the frame's median corner misfit.
MAX_SADDLE_MISFIT = 0.08

#: See :data:`MAX_SADDLE_MISFIT`.
MISFIT_MEDIANS = 2.5

#: ... but never beyond this: in a frame of pure noise the median misfit is above 1, and
#: a loose limit would let a few noise pixels pass for corners.
MISFIT_CEILING = 0.25

#: The saddle check's window reaches this far beyond the refinement's, px: an occluder
#: at the edge of the refinement window, where ``cornerSubPix`` still reads it, needs
#: pixels around it to show in the misfit.
CHECK_MARGIN_PX = 2

#: A corner further than this many times the median corner residual from the homography
#: through the others is an outlier (the residual of a good corner is Rayleigh distributed:
#: beyond 4 medians lies a fraction of 1e-5 of them).
OUTLIER_MEDIANS = 4.0

#: ... but never below this, px: at 0.1 px a corner shifts a 12-corner fit by 0.01 px.
OUTLIER_FLOOR_PX = 0.1


@dataclass(frozen=True)
class CornerSelection:
    """The corners a frame's fit may use.

    Attributes:
        mask: Per board corner, whether it is used.
        outside: Corners whose refinement window leaves the image (or whose refinement did
            not converge near the prediction).
        occluded: Corners failing the saddle check (no contrast, wrong colours, an occluder
            in the window).
        outliers: Corners dropped for missing the homography through the others.
    """

    mask: np.ndarray
    outside: int
    occluded: int
    outliers: int

    @property
    def count(self) -> int:
        """Corners used."""
        return int(np.count_nonzero(self.mask))

    def describe(self) -> str:
        """One line: how many corners are used and why the others are not."""
        dropped = [
            f'{n} {what}'
            for n, what in (
                (self.outside, 'out of view'),
                (self.occluded, 'occluded'),
                (self.outliers, 'outliers'),
            )
            if n
        ]
        return f'{self.count} of {self.mask.size} corners' + (
            f' ({", ".join(dropped)})' if dropped else ''
        )


def grid_axes(grid: np.ndarray, pattern_size: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
    """Image vectors of one square along the board's x and y axes at every corner.

    Args:
        grid: All corners (N x 2, finite), row-major board order, e.g. a prediction.
        pattern_size: ``(corners per row, rows)``.

    Returns:
        ``(along_x, along_y)``, each N x 2, by central differences (one-sided at the border).
    """
    cols, rows = pattern_size
    g = np.asarray(grid, dtype=float).reshape(rows, cols, 2)
    return _differences(g, 1).reshape(-1, 2), _differences(g, 0).reshape(-1, 2)


def _differences(g: np.ndarray, axis: int) -> np.ndarray:
    """``np.gradient`` of a rows x cols x 2 grid along ``axis``, for every frame.

    Central differences inside, one-sided at the ends, without ``np.gradient``'s generality.
    """
    out = np.zeros_like(g)
    if g.shape[axis] < 2:
        return out
    if axis == 0:
        out[1:-1] = (g[2:] - g[:-2]) / 2.0
        out[0] = g[1] - g[0]
        out[-1] = g[-1] - g[-2]
    else:
        out[:, 1:-1] = (g[:, 2:] - g[:, :-2]) / 2.0
        out[:, 0] = g[:, 1] - g[:, 0]
        out[:, -1] = g[:, -1] - g[:, -2]
    return out


#: Samples of ``erf`` per unit of its argument in :data:`_ERF_TABLE`: the nearest entry is
#: within 1.13 / (2 * 1024) = 5.5e-4 of ``erf``, under 2 % of the clean corners' misfit and a
#: tenth of the 2 DN noise's share of it.
_ERF_SAMPLES = 1024

#: Where ``erf`` is tabulated, in its argument: beyond 6 it is 1 to 2e-17.
_ERF_REACH = 6.0

#: ``erf`` on ``[-_ERF_REACH, _ERF_REACH]`` every ``1 / _ERF_SAMPLES``: a table look-up is some
#: 7 times faster than ``scipy.special.erf``, and the saddle check runs on every frame.
_ERF_TABLE = erf(
    np.arange(-_ERF_REACH * _ERF_SAMPLES, _ERF_REACH * _ERF_SAMPLES + 1) / _ERF_SAMPLES
)


def _erf_of_affine(
    slope_x: np.ndarray,
    slope_y: np.ndarray,
    intercept: np.ndarray,
    ox: np.ndarray,
    oy: np.ndarray,
) -> np.ndarray:
    """``erf(slope_x ox + slope_y oy + intercept)`` from :data:`_ERF_TABLE` (nearest entry).

    Args:
        slope_x: Coefficients of ``ox`` (any shape ending in 1, broadcast against ``ox``).
        slope_y: Coefficients of ``oy``, the same shape.
        intercept: Constant terms, the same shape.
        ox: Pixel offsets along x (the last axis runs over a window's pixels).
        oy: Pixel offsets along y, the shape of ``ox``.

    Returns:
        The broadcast array of ``erf`` values.
    """
    reach = _ERF_REACH * _ERF_SAMPLES
    # Scaled to table entries and shifted by half an entry, so truncation rounds.
    index = (slope_x * _ERF_SAMPLES) * ox
    index += (slope_y * _ERF_SAMPLES) * oy
    index += intercept * _ERF_SAMPLES + (reach + 0.5)
    np.clip(index, 0.0, 2.0 * reach, out=index)
    return np.asarray(_ERF_TABLE.take(index.astype(np.intp)))


@functools.lru_cache(maxsize=8)
def _window_offsets(radius: int) -> tuple[np.ndarray, np.ndarray]:
    """Pixel offsets ``(ox, oy)`` of a ``2 radius + 1`` square window, row-major (1-D each)."""
    offsets = np.arange(-radius, radius + 1)
    oy, ox = np.meshgrid(offsets, offsets, indexing='ij')
    return ox.ravel(), oy.ravel()


def saddle_fit(
    image: np.ndarray,
    corners: np.ndarray,
    along_x: np.ndarray,
    along_y: np.ndarray,
    radius: int,
    blurs: tuple[float, ...] = BLURS_PX,
) -> tuple[np.ndarray, np.ndarray]:
    """Fits a blurred checkerboard corner to the window around each corner.

    The model of a corner at ``c`` whose edges run along ``along_x`` and ``along_y`` is
    ``I = m + A erf(s_x / sigma) erf(s_y / sigma)``, where ``s_x`` and ``s_y`` are a pixel's
    signed distances (px) to the two edge lines: a Gaussian blur of the ideal saddle (exact
    for square cells; ``erf`` from a table, within 5.5e-4). ``m`` and ``A`` are fitted
    linearly for each blur in ``blurs``, and the best blur is kept. The model is centred on
    the refined corner, so an occluder that pulled the refinement off shows in the misfit
    twice: in its own pixels and in the true edges, now off-centre.

    Args:
        image: Grey image (H x W).
        corners: Refined corners (M x 2), finite.
        along_x: Image vector of one square along the board's x axis at each corner (M x 2).
        along_y: The same along y (M x 2).
        radius: The window is ``2 radius + 1`` pixels square, centred on the corner.
        blurs: Gaussian sigmas to try, px.

    Returns:
        ``(amplitude, misfit)`` per corner: ``A`` (signed, DN; positive when the corner's
        ``(+x, +y)`` quadrant is light), and the rms residual over ``|A|``.
    """
    corners = np.asarray(corners, dtype=float).reshape(-1, 2)
    h, w = image.shape[:2]
    ox, oy = _window_offsets(radius)
    centre = np.rint(corners).astype(np.int64)
    inside = (
        centre.size == 0
        or (centre.min(axis=0) >= radius).all()
        and centre[:, 0].max() < w - radius
        and centre[:, 1].max() < h - radius
    )
    if inside and image.flags.c_contiguous:
        # Every window in the image: one gather through flat indices, offsets whole pixels.
        flat = (centre[:, 1] * w + centre[:, 0])[:, None] + (oy * w + ox)
        values = image.reshape(-1).take(flat).astype(np.float64)
        wx, wy = ox, oy
    else:
        px = np.clip(centre[:, 0, None] + ox, 0, w - 1)
        py = np.clip(centre[:, 1, None] + oy, 0, h - 1)
        values = image[py, px].astype(np.float64)
        wx = (px - centre[:, 0, None]).astype(np.float64)
        wy = (py - centre[:, 1, None]).astype(np.float64)
    shift = centre - corners
    # Signed distance to the edge line along x (the board's y = const) and along y, as
    # linear functions of the window offset: s = a wx + b wy + (a, b) . (centre - corner).
    unit_x = along_x / np.maximum(np.linalg.norm(along_x, axis=1), 1e-9)[:, None]
    unit_y = along_y / np.maximum(np.linalg.norm(along_y, axis=1), 1e-9)[:, None]
    orient = np.sign(unit_x[:, 0] * unit_y[:, 1] - unit_x[:, 1] * unit_y[:, 0])
    # (coefficient of dx, coefficient of dy) of s_x and of s_y.
    sx = np.stack([unit_y[:, 1], -unit_y[:, 0]], axis=1) * orient[:, None]
    sy = np.stack([-unit_x[:, 1], unit_x[:, 0]], axis=1) * orient[:, None]
    n = values.shape[1]
    # All blurs at once (blur x corner x pixel): this runs on every frame.
    scale = (1.0 / (np.sqrt(2.0) * np.asarray(blurs, dtype=float)))[:, None, None]

    def erf_of(coefficients: np.ndarray) -> np.ndarray:
        a = coefficients[:, 0, None] * scale
        b = coefficients[:, 1, None] * scale
        c = (coefficients * shift).sum(axis=1)[:, None] * scale
        return _erf_of_affine(a, b, c, wx, wy)

    shape = erf_of(sx)
    shape *= erf_of(sy)
    # Linear least squares for m and A, per blur and corner, in closed form; the residual
    # sum of squares follows from the moments, n (var_v - A cov), without the residuals.
    mean_v = values.mean(axis=1)
    var_v = np.einsum('mn,mn->m', values, values) / n - mean_v**2
    mean_s = shape.mean(axis=2)
    var_s = np.einsum('kmn,kmn->km', shape, shape) / n - mean_s**2
    cov = np.einsum('kmn,mn->km', shape, values) / n - mean_s * mean_v
    amplitude = cov / np.maximum(var_s, 1e-12)
    sum_squares = np.maximum(n * (var_v - amplitude * cov), 0.0)
    with np.errstate(divide='ignore', invalid='ignore'):
        misfit = np.sqrt(sum_squares / max(n - 2, 1)) / np.abs(amplitude)
    misfit = np.where(np.isfinite(misfit), misfit, np.inf)
    # The first best blur, as a strict improvement over the blurs in order would keep.
    best = np.argmin(misfit, axis=0)
    columns = np.arange(len(corners))
    best_misfit = misfit[best, columns]
    best_amplitude = np.where(np.isfinite(best_misfit), amplitude[best, columns], 0.0)
    return best_amplitude, best_misfit


def checked_saddle_fit(
    image: np.ndarray,
    corners: np.ndarray,
    along_x: np.ndarray,
    along_y: np.ndarray,
    radius: int,
) -> tuple[np.ndarray, np.ndarray]:
    """:func:`saddle_fit` over :data:`BLURS_PX`, trying every blur only where it matters.

    Every corner is fitted with :data:`FIRST_BLUR_PX`; those missing it by more than
    :data:`MAX_SADDLE_MISFIT` try the other blurs, and so do all the rest when the median
    misfit exceeds ``MAX_SADDLE_MISFIT / MISFIT_MEDIANS`` while a corner still misses the
    limit's floor. The misfit limit of :func:`select_corners` then decides every corner
    exactly as with all blurs: a misfit kept from the first blur is at most the limit's
    floor, and either the median stays below the point where it would raise the limit or
    every misfit is within the floor, so every corner passes either way. Only such a
    corner's amplitude comes from a blur that fits it well but perhaps not best.

    Args:
        image: Grey image (H x W).
        corners: Refined corners (M x 2), finite.
        along_x: Image vector of one square along the board's x axis at each corner (M x 2).
        along_y: The same along y (M x 2).
        radius: The window is ``2 radius + 1`` pixels square, centred on the corner.

    Returns:
        ``(amplitude, misfit)`` per corner, as from :func:`saddle_fit`.
    """
    amplitude, misfit = saddle_fit(image, corners, along_x, along_y, radius, (FIRST_BLUR_PX,))
    others = tuple(b for b in BLURS_PX if b != FIRST_BLUR_PX)

    def search(which: np.ndarray) -> None:
        index = np.flatnonzero(which)
        if index.size == 0 or not others:
            return
        a, m = saddle_fit(image, corners[index], along_x[index], along_y[index], radius, others)
        better = m < misfit[index]
        misfit[index[better]] = m[better]
        amplitude[index[better]] = a[better]

    rough = misfit > MAX_SADDLE_MISFIT
    search(rough)
    # With every misfit within the limit's floor, the limit passes them all whatever the
    # median: the other corners' best misfits cannot change a decision.
    if np.any(misfit > MAX_SADDLE_MISFIT) and (
        sorted_median(misfit) > MAX_SADDLE_MISFIT / MISFIT_MEDIANS
    ):
        search(~rough)
    return amplitude, misfit


@functools.lru_cache(maxsize=8)
def corner_parity(pattern_size: tuple[int, int]) -> np.ndarray:
    """+1 or -1 per corner: the sign of its saddle relative to corner 0 (they alternate).

    The array is shared between calls (read-only).
    """
    cols, rows = pattern_size
    r, c = np.divmod(np.arange(cols * rows), cols)
    parity = np.where((r + c) % 2 == 0, 1.0, -1.0)
    parity.flags.writeable = False
    return parity


def reject_outliers(
    object_xy: np.ndarray, ideal: np.ndarray, mask: np.ndarray, min_corners: int
) -> np.ndarray:
    """Drops corners that miss a homography through the others, worst first.

    Args:
        object_xy: Board-plane corner coordinates (N x 2).
        ideal: Undistorted corner pixels (N x 2; rows outside ``mask`` are ignored).
        mask: Corners to consider.
        min_corners: Stop dropping below this many (the caller then refuses the frame).

    Returns:
        The reduced mask.
    """
    mask = mask.copy()
    while np.count_nonzero(mask) >= max(min_corners, 5):
        index = np.flatnonzero(mask)
        src = object_xy[index].astype(np.float64)
        dst = ideal[index].astype(np.float64)
        h, _ = cv2.findHomography(src, dst, 0)
        if h is None or not np.all(np.isfinite(h)):
            mask[:] = False
            break
        mapped = src @ h[:, :2].T + h[:, 2]
        residual = np.linalg.norm(mapped[:, :2] / mapped[:, 2:3] - dst, axis=1)
        worst = int(np.argmax(residual))
        limit = max(OUTLIER_MEDIANS * sorted_median(residual), OUTLIER_FLOOR_PX)
        if residual[worst] <= limit:
            break
        mask[index[worst]] = False
    return mask


def coverage_problem(
    object_xy: np.ndarray, mask: np.ndarray, min_corners: int, min_spread: float, square: float
) -> str:
    """Whether the used corners pin the pose down; the reason when they do not.

    Args:
        object_xy: Board-plane corner coordinates (N x 2), m.
        mask: Corners used.
        min_corners: Fewest corners accepted.
        min_spread: Least rms spread of the corners across their weakest direction,
            in squares (two adjacent full rows: 0.5).
        square: Square size, m.

    Returns:
        ``''`` when enough, else one line.
    """
    n = int(np.count_nonzero(mask))
    if n < min_corners:
        return f'only {n} of {mask.size} corners seen, need {min_corners}'
    points = object_xy[mask] / square
    spread = float(np.sqrt(np.linalg.eigvalsh(np.cov(points.T, bias=True))[0]))
    # Two full rows sit exactly at 0.5: a hair of tolerance for the rounding of the grid.
    if spread < min_spread - 1e-9:
        return (
            f'the {n} corners seen lie along a line (spread {spread:.2f} squares across it, '
            f'need {min_spread:g})'
        )
    return ''


def select_corners(
    image: np.ndarray,
    refined: np.ndarray,
    predicted: np.ndarray,
    pattern_size: tuple[int, int],
    radius: int,
    min_contrast_dn: float,
    polarity: float | None = None,
) -> CornerSelection:
    """Keeps the refined corners that pass the saddle check (before the residual check).

    Args:
        image: Grey image.
        refined: Refined corners (N x 2; NaN where the window left the image or the
            refinement did not converge near the prediction).
        predicted: The prediction of every corner (N x 2, finite): gives the board's axes.
        pattern_size: ``(corners per row, rows)``.
        radius: The refinement window's half-size, px (the check reads
            :data:`CHECK_MARGIN_PX` more).
        min_contrast_dn: Least light-dark difference at a corner, DN.
        polarity: The board's colour order (:func:`board_polarity` of a whole view), or
            ``None`` to take the majority's. A labelling one square off flips it.

    Returns:
        The selection (``outliers`` is 0: see :func:`reject_outliers`).
    """
    found = np.all(np.isfinite(refined), axis=1)
    mask = np.zeros(found.size, dtype=bool)
    if not np.any(found):
        return CornerSelection(mask, int(found.size), 0, 0)
    along_x, along_y = grid_axes(predicted, pattern_size)
    amplitude, misfit = checked_saddle_fit(
        image, refined[found], along_x[found], along_y[found], radius + CHECK_MARGIN_PX
    )
    signed = amplitude * corner_parity(pattern_size)[found]
    # The board's colour order (dark or light square at corner 0) from the majority.
    if polarity is None:
        polarity = 1.0 if sorted_median(signed) >= 0 else -1.0
    limit = min(max(MAX_SADDLE_MISFIT, MISFIT_MEDIANS * sorted_median(misfit)), MISFIT_CEILING)
    good = (signed * polarity >= min_contrast_dn / 2.0) & (misfit <= limit)
    mask[np.flatnonzero(found)[good]] = True
    return CornerSelection(mask, int(np.count_nonzero(~found)), int(np.count_nonzero(~good)), 0)


#: Nearest a colour sample comes to a corner's edge lines, px: at 3 px a 1.8 px blur (the
#: widest of :data:`BLURS_PX`) still leaves 90 % of the saddle's amplitude.
COLOUR_EDGE_PX = 3

#: How far a colour sample may stray from its square's mean, as a fraction of the corner's
#: light-dark difference: a clean corner's samples stray by blur (at most some 7 %) and
#: noise (2 DN of 190 DN), an occluder's by its own contrast with the square.
COLOUR_TOLERANCE = 0.25


@functools.lru_cache(maxsize=8)
def _colour_offsets(radius: int) -> np.ndarray:
    """Board-axis offsets ``(a, b)`` of the colour samples (K x 2), px.

    First the quadrants with ``a b > 0``, then those with ``a b < 0``, every other pixel from
    :data:`COLOUR_EDGE_PX` to ``radius`` from the edge lines. The array is shared between
    calls (read-only).
    """
    steps = np.arange(COLOUR_EDGE_PX, max(radius, COLOUR_EDGE_PX) + 1, 2, dtype=float)
    a, b = (v.ravel() for v in np.meshgrid(steps, steps, indexing='ij'))
    offsets = np.stack([np.concatenate([a, -a, a, -a]), np.concatenate([b, -b, -b, b])], axis=1)
    offsets.flags.writeable = False
    return offsets


def colours_as_expected(
    image: np.ndarray,
    corners: np.ndarray,
    predicted: np.ndarray,
    pattern_size: tuple[int, int],
    radius: int,
    min_contrast_dn: float,
    polarity: float,
) -> bool:
    """Whether every corner shows its four squares in the expected colours, untouched.

    A cheap screen for a clean frame, before :func:`select_corners`: per corner, a sparse
    grid of pixels in each of its four squares, within the saddle check's window but
    :data:`COLOUR_EDGE_PX` away from the edge lines (nearest pixel, no model, no blur
    search). The two light squares' samples must be lighter than the two dark squares' by
    ``min_contrast_dn`` on average, in the colour order of ``polarity``, and every sample
    within :data:`COLOUR_TOLERANCE` of the difference from its squares' mean. A cable, a
    hand or a sheet's edge inside a window changes some samples; a corner off the image
    border, or a pale, noisy or defocused frame, fails too. The screen only decides that
    nothing needs checking: when it fails, the saddle check runs as usual.

    Args:
        image: Grey image (H x W).
        corners: Refined corners (N x 2, all of the board's).
        predicted: The prediction of every corner (N x 2, finite): gives the board's axes.
        pattern_size: ``(corners per row, rows)``.
        radius: The refinement window's half-size, px (the samples reach
            :data:`CHECK_MARGIN_PX` beyond it, as the saddle check does).
        min_contrast_dn: Least light-dark difference at a corner, DN.
        polarity: The board's colour order (:func:`board_polarity`).

    Returns:
        ``True`` when every corner passes.
    """
    if not np.all(np.isfinite(corners)) or not image.flags.c_contiguous:
        return False
    along_x, along_y = grid_axes(predicted, pattern_size)
    # Per corner, the unit vectors of the board's axes as the rows of a 2 x 2 matrix.
    axes = np.stack([along_x, along_y], axis=1)
    axes /= np.maximum(np.hypot(axes[:, :, 0], axes[:, :, 1]), 1e-9)[:, :, None]
    pixel = np.rint(corners[:, None, :] + _colour_offsets(radius + CHECK_MARGIN_PX) @ axes)
    h, w = image.shape[:2]
    if pixel.min() < 0 or pixel[:, :, 0].max() >= w or pixel[:, :, 1].max() >= h:
        return False
    flat = (pixel[:, :, 1] * w + pixel[:, :, 0]).astype(np.intp)
    values = image.reshape(-1).take(flat).reshape(len(corners), 2, -1)
    means = values.mean(axis=2)
    # Positive where the quadrants with a b > 0 (the (+x, +y) one among them) are light.
    contrast = (means[:, 0] - means[:, 1]) * (corner_parity(pattern_size) * polarity)
    stray = np.maximum(values.max(axis=2) - means, means - values.min(axis=2))
    return bool(
        np.all(contrast >= min_contrast_dn)
        and np.all(stray.max(axis=1) <= COLOUR_TOLERANCE * contrast)
    )


def board_polarity(
    image: np.ndarray, corners: np.ndarray, pattern_size: tuple[int, int], radius: int
) -> float:
    """The board's colour order in a view of the whole board: +1 or -1.

    Args:
        image: Grey image.
        corners: All corners (N x 2, finite), in board order.
        pattern_size: ``(corners per row, rows)``.
        radius: The refinement window's half-size, px.

    Returns:
        The sign of corner 0's saddle amplitude, by the majority of all corners.
    """
    along_x, along_y = grid_axes(corners, pattern_size)
    amplitude, _ = saddle_fit(image, corners, along_x, along_y, radius + CHECK_MARGIN_PX)
    return 1.0 if np.median(amplitude * corner_parity(pattern_size)) >= 0 else -1.0


def labelling_is_unambiguous(count: int, pattern_size: tuple[int, int]) -> bool:
    """Whether so many corners were found that the grid cannot be one square off.

    A labelling shifted by a square leaves a whole row or column of predictions over the
    board's blank margin, so it finds at most ``N - min(cols, rows)`` corners.

    Args:
        count: Corners found and verified.
        pattern_size: ``(corners per row, rows)``.

    Returns:
        Whether ``count`` exceeds what any shifted labelling could find.
    """
    cols, rows = pattern_size
    return count > cols * rows - min(cols, rows)
