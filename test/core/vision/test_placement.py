"""The configured checkerboard placed in ``beam_base`` for the viewers."""

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from lumpbeam_ros.core.vision.config import load_camera_config
from lumpbeam_ros.core.vision.placement import board_placement


def test_the_board_placement_is_the_configured_pose():
    config = load_camera_config()
    board = board_placement(config)
    pose, printed = config.rig.base_board, config.rig.board
    np.testing.assert_allclose(board.center, pose.translation)
    assert math.isclose(np.linalg.norm(board.orientation), 1.0)
    np.testing.assert_allclose(
        Rotation.from_quat(board.orientation).as_matrix(), pose.rotation, atol=1e-12
    )
    margin = 2 * printed.margin_squares
    assert board.width_m == pytest.approx((printed.squares_x + margin) * printed.square_size_m)
    assert board.height_m == pytest.approx((printed.squares_y + margin) * printed.square_size_m)
