import cv2
import numpy as np
import pytest

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.vision.camera_model import CameraInfo

DISTORTION = (-0.12, 0.05, 0.001, -0.0015, 0.01)
RATIONAL = (0.3, -0.1, 0.0008, -0.0006, 0.02, 0.45, -0.05, 0.01)
FISHEYE = (-0.05, 0.01, -0.003, 0.0005)

LENSES = [
    ('plumb_bob', (0.0,) * 5),
    ('plumb_bob', DISTORTION),
    ('plumb_bob', (0.25, -0.1, -0.001, 0.001, 0.0)),
    ('plumb_bob', (-0.25, 0.1, 0.001, 0.001, 0.0)),
    ('rational_polynomial', RATIONAL),
    ('equidistant', FISHEYE),
]


def _points() -> np.ndarray:
    rng = np.random.default_rng(3)
    return np.column_stack([rng.uniform(-0.3, 0.3, (50, 2)), rng.uniform(0.8, 1.2, 50)])


def _opencv_project(info: CameraInfo, points: np.ndarray) -> np.ndarray:
    """OpenCV's projection, the peer implementation of each model."""
    if info.distortion_model == 'equidistant':
        pts = points.reshape(-1, 1, 3).astype(np.float64)
        out, _ = cv2.fisheye.projectPoints(pts, np.zeros(3), np.zeros(3), info.k, info.d)
    else:
        out, _ = cv2.projectPoints(points, np.zeros(3), np.zeros(3), info.k, info.d)
    return out.reshape(-1, 2)


@pytest.mark.parametrize(('model', 'distortion'), LENSES)
def test_project_matches_opencv(model, distortion):
    info = CameraInfo.pinhole(2048, 2048, 2400.0, (3.0, -2.0), distortion, model)
    np.testing.assert_allclose(
        info.project(_points()), _opencv_project(info, _points()), atol=1e-8
    )


@pytest.mark.parametrize(('model', 'distortion'), LENSES)
def test_undistort_inverts_the_distortion(model, distortion):
    info = CameraInfo.pinhole(1024, 768, 1200.0, (25.0, -30.0), distortion, model)
    ideal = info.pinhole_only().project(_points())
    np.testing.assert_allclose(info.undistort_pixels(info.project(_points())), ideal, atol=1e-9)


def test_scaled_keeps_the_view_and_the_lens():
    info = CameraInfo.pinhole(
        2048, 2048, 2400.0, distortion=FISHEYE, distortion_model='equidistant'
    )
    small = info.scaled(640, 480)
    assert small.k[0, 0] == pytest.approx(750.0)
    assert small.k[0, 2] == pytest.approx(319.5)
    assert small.k[1, 2] == pytest.approx(239.5)
    assert small.distortion_model == 'equidistant'
    np.testing.assert_array_equal(small.d, FISHEYE)


def test_image_size_must_match():
    info = CameraInfo.pinhole(1024, 768, 1200.0)
    info.check_image_size(1024, 768)
    with pytest.raises(LumpbeamError, match='1024 x 768 px but the frame is 640 x 480'):
        info.check_image_size(640, 480, 'frame')


@pytest.mark.parametrize(
    ('kwargs', 'message'),
    [
        ({'width': 0, 'height': 10, 'k': np.eye(3)}, 'size'),
        ({'width': 20000, 'height': 20000, 'k': np.eye(3)}, r'each side 1 to 16384 px'),
        ({'width': 10, 'height': 10, 'k': np.eye(2)}, 'K must'),
        ({'width': 10, 'height': 10, 'k': -np.eye(3)}, 'K must'),
        ({'width': 10, 'height': 10, 'k': np.zeros((3, 3))}, 'K = 0'),
        ({'width': 10, 'height': 10, 'k': np.eye(3), 'd': np.zeros(4)}, 'plumb_bob needs 5'),
        (
            {'width': 10, 'height': 10, 'k': np.eye(3), 'd': np.zeros(5),
             'distortion_model': 'equidistant'},
            'equidistant needs 4',
        ),
        (
            {'width': 10, 'height': 10, 'k': np.eye(3), 'distortion_model': 'fov'},
            "'fov' is not supported",
        ),
        ({'width': 10, 'height': 10, 'k': np.full((3, 3), np.nan)}, 'K must'),
        # A K scaled by 1e300 once stopped the camera node (OverflowError in the tracker).
        (
            {'width': 640, 'height': 480, 'k': np.diag([800e300, 800e300, 1.0])},
            r'fx 8e\+302, fy 8e\+302 px is no lens for a 640 x 480 image',
        ),
        ({'width': 640, 'height': 480, 'k': np.diag([8e5, 800.0, 1.0])}, 'no lens'),
    ],
)  # fmt: skip
def test_bad_camera_info_is_rejected(kwargs, message):
    with pytest.raises(LumpbeamError, match=message):
        CameraInfo(**kwargs)


def test_the_longest_lens_taken_is_a_thousand_image_sizes():
    CameraInfo(640, 480, np.diag([640e3, 640e3, 1.0]))
