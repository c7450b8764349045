import numpy as np
import pytest

from lumpbeam_ros.core.vision.corners import grid_is_regular, homography_residual, refine_corners
from lumpbeam_ros.core.vision.pose import PlaneModel
from lumpbeam_ros.core.vision.synthetic import SyntheticCamera


@pytest.fixture(scope='module')
def scene(config, rest_pose):
    image = SyntheticCamera(config).render(rest_pose)
    return image, PlaneModel(config.rig, config.camera_info).project(rest_pose)


def test_refinement_converges_from_a_pixel_off(scene):
    image, truth = scene
    rng = np.random.default_rng(1)
    refined = refine_corners(image, truth + rng.uniform(-1.5, 1.5, truth.shape), 5)
    assert np.sqrt(np.mean((refined - truth) ** 2)) < 0.05


def test_refinement_marks_corners_off_the_image_or_missing(scene):
    image, truth = scene
    guess = truth.copy()
    guess[0] = [2.0, 2.0]  # window would leave the image
    guess[1] = [20.0, 20.0]  # plain wall: no corner to find
    refined = refine_corners(image, guess, 5)
    assert np.all(np.isnan(refined[0]))
    assert np.all(np.isfinite(refined[2:]))


def test_homography_residual_catches_a_jumped_corner(config, scene):
    _, truth = scene
    object_xy = config.rig.board.object_points()[:, :2]
    assert homography_residual(object_xy, truth) < 1e-3
    jumped = truth.copy()
    jumped[10] = truth[11]
    assert homography_residual(object_xy, jumped) > 5.0
    assert homography_residual(object_xy, np.full_like(truth, np.nan)) == float('inf')


def test_grid_regularity(config, scene):
    _, truth = scene
    pattern = config.rig.board.pattern_size
    assert grid_is_regular(truth, pattern)
    swapped = truth.copy()
    swapped[[3, 4]] = swapped[[4, 3]]
    assert not grid_is_regular(swapped, pattern)
    collapsed = truth.copy()
    collapsed[5] = collapsed[4] + 0.5
    assert not grid_is_regular(collapsed, pattern)
