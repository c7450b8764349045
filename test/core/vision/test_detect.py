import cv2
import numpy as np
import pytest

from lumpbeam_ros.core.vision.detect import (
    canonical_order,
    detect_board,
    detection_scale,
    snap_window,
)
from lumpbeam_ros.core.vision.pose import PlaneModel
from lumpbeam_ros.core.vision.synthetic import SyntheticCamera

from .real_photos import CAMERAS, PATTERN, opencv_corners, photographs

AXES = np.eye(2)  # board x to image right, board y to image down (the default rig)


@pytest.mark.parametrize('max_side', [320, 640])
def test_detects_all_corners_in_board_order(config, rest_pose, max_side):
    image = SyntheticCamera(config).render(rest_pose)
    truth = PlaneModel(config.rig, config.camera_info).project(rest_pose)
    corners = detect_board(image, config.rig.board.pattern_size, AXES, max_side, 5)
    assert corners is not None
    assert np.max(np.linalg.norm(corners - truth, axis=1)) < 0.1


@pytest.mark.parametrize('flip', ['none', 'columns', 'rows', 'both'])
def test_canonical_order_undoes_any_labelling(flip):
    xs, ys = np.meshgrid(np.arange(8) * 10.0, np.arange(6) * 10.0)
    grid = np.stack([xs, ys], axis=-1)
    labelled = {
        'none': grid,
        'columns': grid[:, ::-1],
        'rows': grid[::-1],
        'both': grid[::-1, ::-1],
    }[flip]
    result = canonical_order(labelled.reshape(-1, 2), (8, 6), AXES)
    np.testing.assert_array_equal(result, grid.reshape(-1, 2))


def _turned_grid(angle_deg: float, shear_deg: float) -> np.ndarray:
    """A 9 x 6 grid seen from the board's front, its x axis at ``angle_deg`` in the image.

    The y axis is at ``angle_deg + 90 - shear_deg`` (perspective shears a turned board).
    """
    ax, ay = np.radians(angle_deg), np.radians(angle_deg + 90.0 - shear_deg)
    x_axis = 30.0 * np.array([np.cos(ax), np.sin(ax)])
    y_axis = 30.0 * np.array([np.cos(ay), np.sin(ay)])
    c, r = np.meshgrid(np.arange(9), np.arange(6))
    return np.asarray(300.0 + c[..., None] * x_axis + r[..., None] * y_axis)


@pytest.mark.parametrize('angle', [0, 40, 85, 95, 130, 180, 265, 275, 320])
@pytest.mark.parametrize('shear', [-12, 0, 12])
@pytest.mark.parametrize('flip', ['none', 'columns', 'rows', 'both'])
def test_canonical_order_never_mirrors_a_turned_board(angle, shear, flip):
    """A board turned near 90 degrees keeps its front: its labelling or that turned by 180."""
    grid = _turned_grid(angle, shear)
    labelled = {'none': grid, 'columns': grid[:, ::-1], 'rows': grid[::-1]}
    labelled['both'] = grid[::-1, ::-1]
    result = canonical_order(labelled[flip].reshape(-1, 2), (9, 6), AXES)
    truth = grid.reshape(-1, 2)
    assert np.array_equal(result, truth) or np.array_equal(result, truth[::-1])
    if abs(angle) < 60 or angle > 300:
        np.testing.assert_array_equal(result, truth)  # the nearer of the two


def test_snap_window_is_a_quarter_of_the_shortest_spacing():
    grid = _turned_grid(30, 0).reshape(-1, 2) * (34 / 30)
    assert snap_window(grid, (9, 6)) == 8  # 34 px squares, as in the real photographs
    squeezed = _turned_grid(0, 0).reshape(-1, 2) * np.array([1.0, 0.4])  # 12 px rows
    assert snap_window(squeezed, (9, 6)) == 3
    assert snap_window(grid / 100.0, (9, 6)) == 2  # never below 2 px


@pytest.mark.parametrize('camera', CAMERAS)
@pytest.mark.parametrize('half_window', [3, 4, 5])
def test_real_photographs_give_opencvs_corners_seen_from_the_front(camera, half_window):
    """Every photograph where plain OpenCV finds the board: the same corners, not mirrored.

    OpenCV labels this board (10 x 7 squares) from its colours; the detector, which has only
    the expected orientation, gives that labelling or the same turned by 180 degrees, never a
    mirrored one, whatever tracking window it is handed: the detector's own corners can be
    3.3 px off, more than a 3 px window pulls back.
    """
    for path in photographs(camera):
        gray = cv2.imread(str(path), cv2.IMREAD_GRAYSCALE)
        reference = opencv_corners(gray)
        assert reference is not None, path.name
        corners = detect_board(gray, PATTERN, AXES, 640, half_window, snap_to_grid=True)
        assert corners is not None, path.name
        gap = min(
            np.max(np.linalg.norm(corners - reference, axis=1)),
            np.max(np.linalg.norm(corners[::-1] - reference, axis=1)),
        )
        assert gap < 0.5, f'{path.name}: {gap:.2f} px from OpenCV'


def test_no_board_gives_none(config):
    blank = np.full((config.camera_info.height, config.camera_info.width), 110, np.uint8)
    assert detect_board(blank, config.rig.board.pattern_size, AXES, 640, 5) is None


def test_detection_scale():
    assert detection_scale(2048, 2048, 640) == 4
    assert detection_scale(640, 480, 640) == 1
