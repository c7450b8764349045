"""Sub-pixel corner refinement and the checks that a set of corners is a whole board.

Refinement is OpenCV's ``cornerSubPix``: every image gradient near a corner is orthogonal
to the vector from the corner to its pixel, and the corner is the weighted least-squares
point satisfying that. (A NumPy version vectorized over the 48 corners was measured 4 to 6
times slower and no more accurate, so it was dropped.)
"""

from __future__ import annotations

import cv2
import numpy as np


def refine_corners(
    image: np.ndarray, guess: np.ndarray, half_window: int, max_iterations: int = 10
) -> np.ndarray:
    """Refines corner positions to sub-pixel accuracy with OpenCV's ``cornerSubPix``.

    ``cornerSubPix`` re-centres its window on the estimate at every iteration (bilinear
    resampling), so the window is symmetric about the corner at convergence and the estimate
    carries no window-placement bias. It only reads the windows, so its cost does not grow
    with the image.

    Args:
        image: Grey image (uint8), H x W.
        guess: Initial corners (N x 2), px; within about ``half_window / 2`` of the truth.
        half_window: Window half-size, px; smaller than half a square.
        max_iterations: Iterations at most per corner (it stops at 0.001 px steps).

    Returns:
        Refined corners (N x 2, float64); a corner whose window leaves the image, or that
        moved further than the window from its guess (no corner there), is NaN.
    """
    w = int(half_window)
    guess = np.asarray(guess, dtype=np.float64).reshape(-1, 2)
    h_img, w_img = image.shape[:2]
    # NaN fails every comparison, so a corner not predicted is outside too.
    inside = (
        (guess[:, 0] >= w + 1)
        & (guess[:, 0] <= w_img - w - 2)
        & (guess[:, 1] >= w + 1)
        & (guess[:, 1] <= h_img - w - 2)
    )
    criteria = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_MAX_ITER, max_iterations, 0.001)
    if inside.all():
        pts = guess.astype(np.float32).reshape(-1, 1, 2)
        refined = cv2.cornerSubPix(image, pts, (w, w), (-1, -1), criteria).reshape(-1, 2)
        refined = refined.astype(np.float64)
    else:
        refined = np.full_like(guess, np.nan)
        if not np.any(inside):
            return refined
        pts = np.ascontiguousarray(guess[inside], dtype=np.float32).reshape(-1, 1, 2)
        out = cv2.cornerSubPix(image, pts, (w, w), (-1, -1), criteria).reshape(-1, 2)
        refined[inside] = out
    moved = np.abs(refined - guess).max(axis=1)
    refined[~(moved <= w)] = np.nan
    return refined


def corner_contrast(image: np.ndarray, corners: np.ndarray, offset: int) -> np.ndarray:
    """Saddle strength at each corner: the two diagonals' grey levels, differenced.

    A checkerboard corner has dark squares on one diagonal and light ones on the other; an
    occluded corner, or one sitting on a blank wall, has no such difference, whatever
    ``cornerSubPix`` returned for it.

    Args:
        image: Grey image, H x W.
        corners: Corners (N x 2), finite and at least ``offset`` px inside the image.
        offset: Distance of the diagonal samples from the corner along x and y, px.

    Returns:
        ``|I(+,+) + I(-,-) - I(+,-) - I(-,+)| / 2`` per corner, in grey levels.
    """
    h, w = image.shape[:2]
    centre = np.rint(corners).astype(np.int64)
    x = np.clip(centre[:, 0, None] + offset * np.array([1, -1, 1, -1]), 0, w - 1)
    y = np.clip(centre[:, 1, None] + offset * np.array([1, -1, -1, 1]), 0, h - 1)
    v = image[y, x].astype(np.float64)
    return np.asarray(np.abs(v[:, 0] + v[:, 1] - v[:, 2] - v[:, 3]) / 2.0)


def homography_residual(object_xy: np.ndarray, pixels: np.ndarray) -> float:
    """Largest distance between the corners and a homography fitted through all of them.

    A planar board seen by a pinhole camera maps to the image by a homography, so a corner
    that jumped to a neighbour, an occluded corner or corrupt data shows up here without
    any assumption about the tip's motion.

    Args:
        object_xy: Board-plane corner coordinates (N x 2).
        pixels: Undistorted corner pixels (N x 2).

    Returns:
        The largest residual, px; infinity when no homography fits.
    """
    if not np.all(np.isfinite(pixels)):
        return float('inf')
    h, _ = cv2.findHomography(object_xy.astype(np.float64), pixels.astype(np.float64), 0)
    if h is None or not np.all(np.isfinite(h)):
        return float('inf')
    mapped = object_xy @ h[:, :2].T + h[:, 2]
    if np.any(np.abs(mapped[:, 2]) < 1e-12):
        return float('inf')
    mapped = mapped[:, :2] / mapped[:, 2:3]
    return float(np.max(np.linalg.norm(mapped - pixels, axis=1)))


def grid_is_regular(pixels: np.ndarray, pattern_size: tuple[int, int]) -> bool:
    """Checks the cell geometry: the corner grid is not folded and no cell collapsed.

    Args:
        pixels: Corners (N x 2) in row-major board order.
        pattern_size: ``(corners per row, rows)``.

    Returns:
        Whether every cell has the same orientation (no fold) and no edge is shorter than
        1 px or than a quarter of the longest (no collapse onto a neighbour).
    """
    cols, rows = pattern_size
    grid = pixels.reshape(rows, cols, 2)
    along = np.linalg.norm(np.diff(grid, axis=1), axis=2)
    down = np.linalg.norm(np.diff(grid, axis=0), axis=2)
    shortest = min(along.min(), down.min())
    longest = max(along.max(), down.max())
    if not (shortest > 1.0 and shortest > 0.25 * longest):
        return False
    a = grid[:-1, 1:] - grid[:-1, :-1]
    b = grid[1:, :-1] - grid[:-1, :-1]
    cross = a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]
    return bool(np.all(cross > 0) or np.all(cross < 0))
