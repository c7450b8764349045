"""The independent renderer, checked against OpenCV (not against the tracker's own code)."""

import dataclasses
import subprocess
import sys

import cv2
import numpy as np
import pytest

from lumpbeam_lab.camera.raycast_camera import (
    Lens,
    Optics,
    RaycastCamera,
    Scene,
    lens_distort,
    lens_rays,
)
from lumpbeam_ros.base.errors import LumpbeamError

SCENE = Scene(
    9, 7, 0.06, 1.0, (0.0, 0.05, 0.0), (-np.pi / 2 + 0.02, 0.0, -0.03),
    (2.3107, 1.0, -0.01), (-np.pi / 2, 0.06, 0.0),
)  # fmt: skip
LENSES = [
    ('plumb_bob', (-0.25, 0.1, 1e-3, -1e-3, 0.0)),
    ('plumb_bob', (0.25, -0.1, -1e-3, 1e-3, 0.0)),
    ('rational_polynomial', (0.3, -0.1, 5e-4, -5e-4, 0.02, 0.45, -0.05, 0.01)),
    ('equidistant', (-0.05, 0.01, -0.003, 0.0005)),
]


def _lens(model, coefficients, size=512):
    f = 1200.0 * size / 1024
    return Lens(size, size, f, f, (size - 1) / 2 + 9.0, (size - 1) / 2 - 6.0, model, coefficients)


def _k_d(lens):
    k = np.array([[lens.fx, 0, lens.cx], [0, lens.fy, lens.cy], [0, 0, 1.0]])
    return k, np.array(lens.coefficients)


@pytest.mark.parametrize(('model', 'coefficients'), LENSES)
def test_lens_model_and_its_inverse_match_opencv(model, coefficients):
    lens = _lens(model, coefficients)
    rng = np.random.default_rng(0)
    pts = np.column_stack([rng.uniform(-0.35, 0.35, (40, 2)), np.ones(40)])
    k, d = _k_d(lens)
    if model == 'equidistant':
        theirs, _ = cv2.fisheye.projectPoints(
            pts.reshape(-1, 1, 3), np.zeros(3), np.zeros(3), k, d
        )
    else:
        theirs, _ = cv2.projectPoints(pts, np.zeros(3), np.zeros(3), k, d)
    xd, yd = lens_distort(lens, pts[:, 0], pts[:, 1])
    ours = np.column_stack([xd * lens.fx + lens.cx, yd * lens.fy + lens.cy])
    np.testing.assert_allclose(ours, theirs.reshape(-1, 2), atol=1e-8)
    x, y = lens_rays(lens, ours[:, 0], ours[:, 1])
    np.testing.assert_allclose(np.column_stack([x, y]), pts[:, :2], atol=1e-11)


def _board_in_camera(tip_pose):
    """The scene's transform, composed here with OpenCV's Rodrigues (a second derivation)."""

    def rpy(r, p, y):
        return (
            cv2.Rodrigues(np.array([0, 0, y]))[0]
            @ cv2.Rodrigues(np.array([0, p, 0]))[0]
            @ cv2.Rodrigues(np.array([r, 0, 0]))[0]
        )

    tip_r = cv2.Rodrigues(np.array([0, tip_pose[2], 0.0]))[0]
    cam_r = tip_r @ rpy(*SCENE.mount_rpy)
    cam_t = tip_r @ np.array(SCENE.mount_xyz) + [tip_pose[0], 0, tip_pose[1]]
    board_r = rpy(*SCENE.board_rpy)
    return cam_r.T @ board_r, cam_r.T @ (np.array(SCENE.board_xyz) - cam_t)


@pytest.mark.parametrize(('model', 'coefficients'), LENSES[::2])
def test_corners_are_where_opencv_projects_them(model, coefficients):
    """OpenCV's corner finder on the rendered frame agrees with OpenCV's projection."""
    lens = _lens(model, coefficients)
    camera = RaycastCamera(lens, SCENE, Optics(defocus_px=1.0))
    pose = np.array([2.3107, -0.012, 0.004])
    image = camera.render(np.stack([pose] * 3))
    found, corners = cv2.findChessboardCorners(image, (8, 6))
    assert found
    corners = cv2.cornerSubPix(
        image,
        corners,
        (5, 5),
        (-1, -1),
        (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_COUNT, 50, 1e-4),
    ).reshape(-1, 2)
    u = (np.arange(8) - 3.5) * 0.06
    v = (np.arange(6) - 2.5) * 0.06
    obj = np.array([[a, b, 0.0] for b in v for a in u])
    r, t = _board_in_camera(pose)
    k, d = _k_d(lens)
    truth, _ = cv2.projectPoints(obj, cv2.Rodrigues(r)[0], t, k, d)
    truth = truth.reshape(-1, 2)
    # Match labellings (the detector may start from either end).
    error = corners - truth[np.linalg.norm(corners[:, None] - truth[None], axis=2).argmin(1)]
    # No offset (a pixel-centre or board convention error would show here); the scatter is
    # cornerSubPix's own on sharp edges.
    assert np.all(np.abs(error.mean(axis=0)) < 0.01)
    assert np.sqrt(np.mean(error**2)) < 0.05


def test_motion_blur_centres_on_the_mean_pose_and_noise_is_seeded():
    lens = _lens('plumb_bob', (0.0,) * 5, 256)
    camera = RaycastCamera(lens, SCENE, Optics(noise_dn=2.0, flicker=0.05, seed=3))
    a = camera.render(np.array([[2.3107, -0.01, 0.0]]), 4)
    assert a.dtype == np.uint8 and a.shape == (256, 256)
    np.testing.assert_array_equal(a, camera.render(np.array([[2.3107, -0.01, 0.0]]), 4))
    assert not np.array_equal(a, camera.render(np.array([[2.3107, -0.01, 0.0]]), 5))
    quiet = RaycastCamera(lens, SCENE, Optics())
    blurred = quiet.render(np.array([[2.3107, -0.011, 0.0], [2.3107, -0.009, 0.0]])).astype(float)
    middle = quiet.render(np.array([[2.3107, -0.01, 0.0]])).astype(float)
    # Symmetric motion about the middle pose: the blurred edges straddle the sharp ones.
    assert abs(np.mean(blurred) - np.mean(middle)) < 0.5


def test_bad_lens_and_board_behind_the_camera():
    with pytest.raises(LumpbeamError, match='equidistant'):
        Lens(64, 64, 50.0, 50.0, 32.0, 32.0, 'equidistant', (0.0,) * 5)
    lens = _lens('plumb_bob', (0.0,) * 5, 128)
    behind = dataclasses.replace(SCENE, board_xyz=(2.3107, -1.0, -0.01))
    with pytest.raises(LumpbeamError, match='behind'):
        RaycastCamera(lens, behind, Optics()).render(np.array([2.3107, -0.01, 0.0]))


def test_shares_no_code_with_the_tracker():
    code = (
        'import sys, lumpbeam_lab.camera.raycast_camera; '
        'print(sorted(m for m in sys.modules if m.startswith("lumpbeam_ros.core.vision")))'
    )
    out = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == '[]'
