"""Full checkerboard detection: find the board anywhere in a frame, from scratch.

OpenCV's detector runs on a shrunk copy (it needs only a few pixels per square, and its cost
grows with the image), and its corners are then refined at full resolution. The corner
order is made canonical with the orientation the configured rig implies, because a 180-degree
turned or mirrored labelling of the same grid is equally valid to the detector.
"""

from __future__ import annotations

import math

import cv2
import numpy as np

from lumpbeam_ros.core.vision.corners import refine_corners

_FLAGS = cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE | cv2.CALIB_CB_FAST_CHECK


def detection_scale(width: int, height: int, max_side_px: int) -> int:
    """Integer shrink factor so the detector sees at most ``max_side_px`` on the longer side."""
    return max(1, math.ceil(max(width, height) / max_side_px))


def snap_window(corners: np.ndarray, pattern_size: tuple[int, int]) -> int:
    """Half-size of the window that pulls the detector's corners onto the true ones, px.

    The detector's corners come from the outlines of its quadrangles and can be some pixels
    off (3.3 px on a 640 x 480 photograph whose squares are 34 px), more than a tracking
    window of 3 px can pull back: ``cornerSubPix`` only finds a corner inside its window. A
    window too large fails too: on the 26 real photographs of the tests, half-sizes above
    0.35 to 0.45 of the shortest corner spacing pulled a corner off by 2 to 7 px in 10 of
    them. A quarter of that spacing sits between the two.

    Args:
        corners: The detector's corners (N x 2) in its row-major order, on its image.
        pattern_size: ``(corners per row, rows)``.

    Returns:
        The window half-size, px (at least 2).
    """
    cols, rows = pattern_size
    grid = corners.reshape(rows, cols, 2)
    along = np.linalg.norm(np.diff(grid, axis=1), axis=2)
    down = np.linalg.norm(np.diff(grid, axis=0), axis=2)
    spacing = min(float(along.min()), float(down.min()))
    return max(2, round(spacing / 4))


def canonical_order(
    corners: np.ndarray, pattern_size: tuple[int, int], expected_axes: np.ndarray
) -> np.ndarray:
    """Reorders detected corners into the board's own order, seen from its front.

    The detector labels the grid starting from any of its four corners, so its order may be
    the board's, turned by 180 degrees, or mirrored (which no pose of the board can give:
    it is the board seen through from behind). Of the four labellings, the two with the
    handedness of the expected axes are kept (a board's front turns its x axis towards its
    y axis the same way in every view), and the one whose rows and columns run nearer the
    expected directions wins. A board held turned by some 90 degrees (a handheld target)
    thus still gets a labelling seen from the front, where flipping each direction on its
    own could mirror it.

    Args:
        corners: Corners (N x 2) in the detector's row-major order.
        pattern_size: ``(corners per row, rows)``.
        expected_axes: 2 x 2; row 0 is the image direction of the board's +x axis, row 1 of
            its +y axis.

    Returns:
        The corners in the board's own row-major order.
    """
    cols, rows = pattern_size
    grid = corners.reshape(rows, cols, 2)
    along = np.mean(grid[:, -1] - grid[:, 0], axis=0)
    down = np.mean(grid[-1] - grid[0], axis=0)
    # The detector's rows might run along the board's y axis only for a square pattern,
    # which the configuration rejects; here only their direction along each axis can flip.
    # Flipping one direction mirrors the labelling, flipping both turns it by 180 degrees.
    mirror = 1 if (_cross(along, down) >= 0) == (_cross(*expected_axes) >= 0) else -1
    turned = (along @ expected_axes[0] + mirror * down @ expected_axes[1]) < 0
    sx, sy = (-1, -mirror) if turned else (1, mirror)
    return np.ascontiguousarray(grid[::sy, ::sx].reshape(-1, 2))


def _cross(a: np.ndarray, b: np.ndarray) -> float:
    """The z component of ``a x b`` for image vectors (positive: ``b`` is clockwise on screen)."""
    return float(a[0] * b[1] - a[1] * b[0])


def detect_board(
    image: np.ndarray,
    pattern_size: tuple[int, int],
    expected_axes: np.ndarray,
    max_side_px: int,
    half_window: int,
    snap_to_grid: bool = False,
) -> np.ndarray | None:
    """Finds all inner corners of the board in a grey frame.

    Args:
        image: Grey image (uint8, H x W).
        pattern_size: ``(corners per row, rows)``.
        expected_axes: Image directions of the board's x and y axes (2 x 2).
        max_side_px: The detector's input is shrunk to at most this on its longer side.
        half_window: Refinement window half-size at full resolution, px.
        snap_to_grid: Whether the detector's corners are first pulled in with a window
            sized from the grid it found (:func:`snap_window`), for footage whose squares
            the configuration does not foretell; otherwise with ``half_window`` (scaled to
            the detector's image, 2 to 5 px), which a configured rig sizes for its squares.

    Returns:
        Sub-pixel corners (N x 2) in board order, or ``None`` when the whole board is not
        found.
    """
    h, w = image.shape[:2]
    scale = detection_scale(w, h, max_side_px)
    small = image
    if scale > 1:
        small = cv2.resize(image, (w // scale, h // scale), interpolation=cv2.INTER_AREA)
    try:
        found, corners = cv2.findChessboardCorners(small, pattern_size, flags=_FLAGS)
    except cv2.error:
        return None
    if not found or corners is None or len(corners) != pattern_size[0] * pattern_size[1]:
        return None
    criteria = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_MAX_ITER, 20, 0.01)
    if snap_to_grid:
        small_window = snap_window(corners.reshape(-1, 2), pattern_size)
    else:
        small_window = max(2, min(5, round(half_window / scale)))
    corners = cv2.cornerSubPix(small, corners, (small_window, small_window), (-1, -1), criteria)
    # Pixel centres sit at integers, so a shrunk pixel i covers full pixels scale * i ...
    # scale * (i + 1) - 1, centred at scale * (i + 0.5) - 0.5.
    full = (corners.reshape(-1, 2).astype(np.float64) + 0.5) * scale - 0.5
    full = refine_corners(image, full, half_window)
    if not np.all(np.isfinite(full)):
        return None
    return canonical_order(full, pattern_size, expected_axes)
