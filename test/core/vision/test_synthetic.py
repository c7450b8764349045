import dataclasses

import numpy as np
import pytest

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.vision.camera_model import CameraInfo
from lumpbeam_ros.core.vision.detect import detect_board
from lumpbeam_ros.core.vision.pose import PlaneModel, camera_board_transform
from lumpbeam_ros.core.vision.synthetic import SyntheticCamera


def test_same_seed_same_image_other_seed_other_noise(config, rest_pose):
    a = SyntheticCamera(config, seed=5).render(rest_pose, noise_key=3)
    b = SyntheticCamera(config, seed=5).render(rest_pose, noise_key=3)
    c = SyntheticCamera(config, seed=6).render(rest_pose, noise_key=3)
    assert a.dtype == np.uint8 and a.shape == (480, 640)
    np.testing.assert_array_equal(a, b)
    difference = a.astype(float) - c
    # The difference of two independent 2-DN noises (quantized) has a spread of 2 sqrt(2).
    assert 2.5 < np.std(difference) < 3.2


def test_grey_levels_and_noise(config, rest_pose):
    quiet = dataclasses.replace(
        config, synthetic=dataclasses.replace(config.synthetic, noise_sigma_dn=0.0)
    )
    image = SyntheticCamera(quiet).render(rest_pose)
    assert image[0, 0] == 110  # the wall
    assert image.min() <= 31 and image.max() >= 219  # dark and light squares


def test_corners_render_where_the_camera_model_projects_them(config, rest_pose):
    image = SyntheticCamera(config).render(rest_pose)
    truth = PlaneModel(config.rig, config.camera_info).project(rest_pose)
    corners = detect_board(image, config.rig.board.pattern_size, np.eye(2), 640, 5)
    assert np.sqrt(np.mean((corners - truth) ** 2)) < 0.05


def test_lens_distortion_moves_corners_as_the_model_says(config, rest_pose):
    distorted = dataclasses.replace(
        config,
        camera_info=CameraInfo.pinhole(640, 480, 750.0, distortion=(-0.25, 0.08, 0, 0, 0)),
    )
    image = SyntheticCamera(distorted).render(rest_pose)
    camera_board = camera_board_transform(config.rig, rest_pose)
    truth = distorted.camera_info.project(camera_board.apply(config.rig.board.object_points()))
    pinhole = distorted.camera_info.pinhole_only().project(
        camera_board.apply(config.rig.board.object_points())
    )
    corners = detect_board(image, config.rig.board.pattern_size, np.eye(2), 640, 5)
    assert np.max(np.abs(truth - pinhole)) > 3.0  # the distortion is visible ...
    assert np.sqrt(np.mean((corners - truth) ** 2)) < 0.08  # ... and rendered right


def test_motion_blur_samples_follow_the_image_motion(config):
    camera = SyntheticCamera(config)
    start = np.array([2.3107, -0.01, 0.0])
    assert camera.motion_samples(start, start) == 1
    # 1.5 mm of tip travel is about 1.2 px at 640 x 480: three 0.5 px steps.
    assert camera.motion_samples(start, start + [0.0, 0.0015, 0.0]) == 3
    assert camera.motion_samples(start, start + [0.0, 1.0, 0.0]) == 16


def test_trajectory_frames_carry_truth_at_mid_exposure(config, drop_test):
    trajectory = drop_test.between(2.0, 2.1)
    frames = list(
        SyntheticCamera(config).render_trajectory(
            trajectory.t, trajectory.x, trajectory.z, trajectory.pitch, trajectory.t[[0, 14]]
        )
    )
    assert [f.index for f in frames] == [0, 1]
    np.testing.assert_allclose(frames[1].truth[1], trajectory.z[14], atol=1e-12)
    # At release the tip is at rest; a quarter period later it moves at 0.8 m/s.
    assert frames[0].motion_samples == 1
    assert frames[1].motion_samples >= 2


@pytest.mark.parametrize(
    'arrays',
    [
        ([0.0, 1.0], [0.0, 0.0], [0.0, 0.0], [0.0, 0.0]),
        ([0.0, 1.0, 2.0, 3.0], [0.0] * 3, [0.0] * 4, [0.0] * 4),
        ([0.0, 1.0, 1.0, 3.0], [2.3] * 4, [0.0] * 4, [0.0] * 4),
        ([0.0, 1.0, 2.0, 3.0], [2.3, np.nan, 2.3, 2.3], [0.0] * 4, [0.0] * 4),
    ],
)
def test_bad_trajectories_are_rejected(config, arrays):
    with pytest.raises(LumpbeamError, match='trajectory'):
        next(SyntheticCamera(config).render_trajectory(*map(np.array, arrays)))


def test_board_behind_the_camera_is_an_error(config):
    board = config.rig.base_board
    behind = dataclasses.replace(
        config,
        rig=dataclasses.replace(
            config.rig,
            base_board=dataclasses.replace(board, translation=board.translation * [1, -1, 1]),
        ),
    )
    with pytest.raises(LumpbeamError, match='behind'):
        SyntheticCamera(behind)
