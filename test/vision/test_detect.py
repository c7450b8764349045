import numpy as np
import pytest

from lumpbeam_ros.vision.detect import canonical_order, detect_board, detection_scale
from lumpbeam_ros.vision.pose import PlaneModel
from lumpbeam_ros.vision.synthetic import SyntheticCamera

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


def test_no_board_gives_none(config):
    blank = np.full((config.camera_info.height, config.camera_info.width), 110, np.uint8)
    assert detect_board(blank, config.rig.board.pattern_size, AXES, 640, 5) is None


def test_detection_scale():
    assert detection_scale(2048, 2048, 640) == 4
    assert detection_scale(640, 480, 640) == 1
