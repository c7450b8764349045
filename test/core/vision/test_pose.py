import numpy as np
import pytest

from lumpbeam_ros.core.vision.geometry import rotation_x
from lumpbeam_ros.core.vision.pose import (
    PlaneModel,
    camera_board_transform,
    solve_board_pnp,
    tip_pose_from_board_pose,
)


@pytest.mark.parametrize('pose', [(2.3107, -0.05, 0.03), (2.30, 0.02, -0.01)])
def test_jacobian_matches_finite_differences(config, pose):
    model = PlaneModel(config.rig, config.camera_info)
    pose = np.array(pose)
    _, jac = model.project_with_jacobian(pose)
    for i in range(3):
        step = np.zeros(3)
        step[i] = 1e-7
        numeric = (model.project(pose + step) - model.project(pose - step)) / 2e-7
        np.testing.assert_allclose(jac[:, :, i], numeric, rtol=1e-5, atol=1e-4)


def test_fit_recovers_pose_and_covariance_follows_noise(config, rest_pose):
    model = PlaneModel(config.rig, config.camera_info)
    rng = np.random.default_rng(0)
    exact = model.fit(model.project(rest_pose), rest_pose + [0.002, -0.003, 0.01])
    np.testing.assert_allclose(exact.pose, rest_pose, atol=1e-10)
    assert exact.rms_px < 1e-8
    errors, sigmas = [], []
    for _ in range(300):
        noisy = model.project(rest_pose) + rng.normal(0.0, 0.05, (model.n_points, 2))
        fit = model.fit(noisy, rest_pose)
        errors.append(fit.pose - rest_pose)
        sigmas.append(np.sqrt(np.diag(fit.covariance)))
    # The claimed standard deviations match the scatter within sampling error.
    ratio = np.std(errors, axis=0) / np.mean(sigmas, axis=0)
    np.testing.assert_allclose(ratio, 1.0, atol=0.15)


def test_pnp_never_returns_the_flipped_solution(config, rest_pose):
    model = PlaneModel(config.rig, config.camera_info)
    board = config.rig.board.object_points()
    truth = camera_board_transform(config.rig, rest_pose)
    pixels = model.project(rest_pose)
    # Even when told to expect an orientation 20 degrees off, the good solution wins.
    expected = rotation_x(0.35) @ truth.rotation
    found = solve_board_pnp(board, pixels, config.camera_info, expected)
    assert found is not None
    np.testing.assert_allclose(found.rotation, truth.rotation, atol=1e-6)
    np.testing.assert_allclose(tip_pose_from_board_pose(config.rig, found), rest_pose, atol=1e-6)


def test_pnp_rejects_a_board_seen_from_behind(config, rest_pose):
    model = PlaneModel(config.rig, config.camera_info)
    board = config.rig.board.object_points()
    # Mirrored corners can only come from the board's back side.
    mirrored = board * np.array([-1.0, 1.0, 1.0])
    found = solve_board_pnp(mirrored, model.project(rest_pose), config.camera_info, np.eye(3))
    if found is not None:
        assert np.all(np.isfinite(found.rotation))
        assert found.rotation[:, 2] @ found.translation > 0
