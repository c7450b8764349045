import cv2
import numpy as np
import pytest

from lumpbeam_ros.errors import LumpbeamError
from lumpbeam_ros.vision.camera_model import CameraInfo

DISTORTION = (-0.12, 0.05, 0.001, -0.0015, 0.01)


def _points() -> np.ndarray:
    rng = np.random.default_rng(3)
    return np.column_stack([rng.uniform(-0.3, 0.3, (50, 2)), rng.uniform(0.8, 1.2, 50)])


@pytest.mark.parametrize('distortion', [(0.0,) * 5, DISTORTION])
def test_project_matches_opencv(distortion):
    info = CameraInfo.pinhole(2048, 2048, 2400.0, (3.0, -2.0), distortion)
    ours = info.project(_points())
    theirs, _ = cv2.projectPoints(_points(), np.zeros(3), np.zeros(3), info.k, info.d)
    np.testing.assert_allclose(ours, theirs.reshape(-1, 2), atol=1e-9)


def test_undistort_inverts_the_distortion():
    info = CameraInfo.pinhole(1024, 768, 1200.0, distortion=DISTORTION)
    ideal = info.pinhole_only().project(_points())
    np.testing.assert_allclose(info.undistort_pixels(info.project(_points())), ideal, atol=1e-6)


def test_scaled_keeps_the_view():
    info = CameraInfo.pinhole(2048, 2048, 2400.0)
    small = info.scaled(640, 480)
    assert small.k[0, 0] == pytest.approx(750.0)
    assert small.k[0, 2] == pytest.approx(319.5)
    assert small.k[1, 2] == pytest.approx(239.5)


@pytest.mark.parametrize(
    'kwargs',
    [
        {'width': 0, 'height': 10, 'k': np.eye(3)},
        {'width': 10, 'height': 10, 'k': np.eye(2)},
        {'width': 10, 'height': 10, 'k': -np.eye(3)},
        {'width': 10, 'height': 10, 'k': np.eye(3), 'd': np.zeros(4)},
        {'width': 10, 'height': 10, 'k': np.eye(3), 'distortion_model': 'equidistant'},
        {'width': 10, 'height': 10, 'k': np.full((3, 3), np.nan)},
    ],
)
def test_bad_camera_info_is_rejected(kwargs):
    with pytest.raises(LumpbeamError, match='camera info'):
        CameraInfo(**kwargs)
