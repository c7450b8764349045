import numpy as np
import pytest

from lumpbeam_ros.core.vision.board import Checkerboard
from lumpbeam_ros.core.vision.config import with_board
from lumpbeam_ros.core.vision.partial import board_polarity
from lumpbeam_ros.core.vision.pose import PlaneModel
from lumpbeam_ros.core.vision.synthetic import SyntheticCamera


def test_object_points_are_row_major_and_centred():
    board = Checkerboard(9, 7, 0.06, 1.0)
    points = board.object_points()
    assert board.pattern_size == (8, 6)
    assert points.shape == (48, 3)
    np.testing.assert_allclose(points.mean(axis=0), 0.0, atol=1e-15)
    np.testing.assert_allclose(points[1] - points[0], [0.06, 0.0, 0.0])
    np.testing.assert_allclose(points[8] - points[0], [0.0, 0.06, 0.0])


@pytest.mark.parametrize('n', [4, 10, 33])
def test_texture_edges_fall_where_the_affine_map_says(n):
    board = Checkerboard(9, 7, 0.06, margin_squares=1.0)
    texture, to_board = board.texture(n, dark=10.0, light=200.0)
    assert texture.shape == (9 * n, 11 * n)
    # The first inner corner sits at texel boundary (2n - 0.5, 2n - 0.5): margin + one square.
    corner = to_board @ np.array([2 * n - 0.5, 2 * n - 0.5, 1.0])
    np.testing.assert_allclose(corner[:2], board.object_points()[0, :2], atol=1e-12)
    # Around it: the dark corner square's diagonal neighbour is dark, the others light.
    assert texture[n, n] == 10.0
    assert texture[2 * n - 1, 2 * n - 1] == 10.0
    assert texture[2 * n - 1, 2 * n] == 200.0
    assert texture[0, 0] == 200.0


@pytest.mark.parametrize(('corners', 'swaps'), [((8, 6), False), ((9, 6), True), ((7, 4), True)])
def test_corner_polarity_is_that_of_the_printed_board(config, rest_pose, corners, swaps):
    """The rendered texture, labelled in board order, has corner 0's documented polarity."""
    board_config = with_board(config, corners)
    board = board_config.rig.board
    assert board.turn_swaps_colours is swaps
    image = SyntheticCamera(board_config).render(rest_pose)
    truth = PlaneModel(board_config.rig, board_config.camera_info).project(rest_pose)
    pattern = board.pattern_size
    assert board_polarity(image, truth, pattern, 5) == board.corner_polarity
    # Turned by 180 degrees (the labelling reversed), the colours give it away or not.
    turned = board_polarity(image, truth[::-1], pattern, 5)
    assert (turned != board.corner_polarity) is swaps
