"""Writes the ROS calibration files of the real-photograph set with plain OpenCV.

Usage: ``python tools/calibrate_real_photos.py [DIR]`` (``DIR`` defaults to
``test/data/real_photos``). Each camera's photographs (``DIR/left``, ``DIR/right``) are
calibrated on their own by ``cv2.calibrateCamera`` (plumb_bob, five coefficients) from the
corners of ``findChessboardCorners`` refined by ``cornerSubPix``, the recipe of OpenCV's
calibration tutorial (with a smaller window), and written as ``DIR/left.yaml`` and
``DIR/right.yaml`` in the layout of the ROS camera calibrator. The files were written once and
are committed: the tests take them as inputs, as a user takes the calibrator's files, so
nothing of the product goes into them.
"""

from __future__ import annotations

import sys
from pathlib import Path

import cv2
import numpy as np
import yaml

#: Inner corners of the board, ``(per row, rows)``.
PATTERN = (9, 6)

#: Edge of one square, m. The set does not say; OpenCV's stereo sample takes 1 (unitless), so
#: 25 mm, a common printed size, sets the scale of the translations.
SQUARE_M = 0.025

#: ``cornerSubPix``: half-window 5 (11 x 11 px), 30 iterations, 0.001 px. The tutorial's
#: half-window of 11 pulls corner 26 of ``right02.jpg`` 5 px off (the homography through the
#: others misses it by 4 px), and the photographs' squares are only 20 to 40 px.
SUBPIX_WINDOW = (5, 5)
SUBPIX_CRITERIA = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_MAX_ITER, 30, 0.001)


def board_points() -> np.ndarray:
    """The inner corners in the board's plane (N x 3, m), OpenCV's row-major order."""
    cols, rows = PATTERN
    grid = np.mgrid[0:cols, 0:rows].T.reshape(-1, 2)
    return np.column_stack([grid * SQUARE_M, np.zeros(len(grid))]).astype(np.float32)


def find_corners(gray: np.ndarray) -> np.ndarray | None:
    """Plain OpenCV's corners of a photograph (N x 1 x 2, float32), or ``None``."""
    found, corners = cv2.findChessboardCorners(gray, PATTERN, None)
    if not found:
        return None
    return cv2.cornerSubPix(gray, corners, SUBPIX_WINDOW, (-1, -1), SUBPIX_CRITERIA)


def calibration_yaml(name: str, size: tuple[int, int], k: np.ndarray, d: np.ndarray) -> str:
    """The calibration in the ROS camera calibrator's layout."""
    data = {
        'image_width': size[0],
        'image_height': size[1],
        'camera_name': name,
        'camera_matrix': {'rows': 3, 'cols': 3, 'data': [float(v) for v in k.ravel()]},
        'distortion_model': 'plumb_bob',
        'distortion_coefficients': {'rows': 1, 'cols': 5, 'data': [float(v) for v in d]},
        'rectification_matrix': {'rows': 3, 'cols': 3, 'data': np.eye(3).ravel().tolist()},
        'projection_matrix': {
            'rows': 3,
            'cols': 4,
            'data': [float(v) for v in np.hstack([k, np.zeros((3, 1))]).ravel()],
        },
    }
    return yaml.safe_dump(data, sort_keys=False, default_flow_style=None)


#: Views with the board a calibration needs at least (OpenCV's minimum for K and 5 terms).
MIN_VIEWS = 3


def calibrate(folder: Path) -> tuple[str, float, int]:
    """Calibrates the camera of one folder; returns the YAML, the RMS error and the views.

    Raises:
        ValueError: Fewer than :data:`MIN_VIEWS` photographs show the board, or they differ
            in size (the message names the folder).
    """
    objects, images, sizes = [], [], set()
    for path in sorted(folder.glob('*.jpg')):
        gray = cv2.imread(str(path), cv2.IMREAD_GRAYSCALE)
        if gray is None:
            continue
        corners = find_corners(gray)
        if corners is not None:
            objects.append(board_points())
            images.append(corners)
            sizes.add((gray.shape[1], gray.shape[0]))
    if len(images) < MIN_VIEWS or len(sizes) != 1:
        raise ValueError(
            f'{folder}: {len(images)} JPEG photographs show a {PATTERN[0]}x{PATTERN[1]} board '
            f'in {len(sizes)} image sizes (need {MIN_VIEWS} of one size)'
        )
    size = sizes.pop()
    rms, k, d, _, _ = cv2.calibrateCamera(objects, images, size, None, None)
    return calibration_yaml(folder.name, size, k, d.ravel()[:5]), float(rms), len(images)


def main(argv: list[str]) -> int:
    """Writes ``left.yaml`` and ``right.yaml`` beside the photographs (exit 2 on bad input)."""
    root = Path(argv[1]) if len(argv) > 1 else Path(__file__).resolve().parents[1]
    if len(argv) <= 1:
        root = root / 'test' / 'data' / 'real_photos'
    results = []
    for camera in ('left', 'right'):
        try:
            results.append((camera, *calibrate(root / camera)))
        except ValueError as exc:
            print(f'calibrate_real_photos: {exc}', file=sys.stderr)
            return 2
    for camera, text, rms, views in results:
        (root / f'{camera}.yaml').write_text(text)
        print(f'{camera}: {views} views, RMS reprojection error {rms:.4f} px')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
