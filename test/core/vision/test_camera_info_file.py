import numpy as np
import pytest
from footage import write_calibration

from lumpbeam_ros.base.errors import ConfigError
from lumpbeam_ros.core.vision.camera_info_file import camera_info_from_url, read_camera_info_file
from lumpbeam_ros.core.vision.camera_model import CameraInfo

#: A file as the ROS camera calibrator writes it (yaml-cpp's layout, flow sequences).
CALIBRATOR_OUTPUT = """\
image_width: 1280
image_height: 1024
camera_name: narrow_stereo
camera_matrix:
  rows: 3
  cols: 3
  data: [1203.5, 0, 641.25, 0, 1204.25, 509.75, 0, 0, 1]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [-0.081, 0.021, 0.0004, -0.0003, 0]
rectification_matrix:
  rows: 3
  cols: 3
  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]
projection_matrix:
  rows: 3
  cols: 4
  data: [1190.1, 0, 640.2, 0, 0, 1191.3, 510.1, 0, 0, 0, 1, 0]
"""


def test_reads_the_calibrators_file(tmp_path):
    path = tmp_path / 'cam.yaml'
    path.write_text(CALIBRATOR_OUTPUT)
    info = read_camera_info_file(path)
    assert (info.width, info.height, info.distortion_model) == (1280, 1024, 'plumb_bob')
    np.testing.assert_array_equal(
        info.k, [[1203.5, 0, 641.25], [0, 1204.25, 509.75], [0, 0, 1]]
    )  # K, not P: the raw image is tracked
    np.testing.assert_array_equal(info.d, [-0.081, 0.021, 0.0004, -0.0003, 0])
    assert camera_info_from_url(f'file://{path}').width == 1280
    assert camera_info_from_url(str(path)).height == 1024


def test_round_trip_and_missing_model_is_plumb_bob(tmp_path):
    info = CameraInfo.pinhole(640, 480, 750.0, (3.0, -2.0), (-0.05, 0.01, 0.0, 0.0, 0.0))
    back = read_camera_info_file(write_calibration(tmp_path / 'c.yaml', info, model=None))
    np.testing.assert_array_equal(back.k, info.k)
    np.testing.assert_array_equal(back.d, info.d)
    assert back.distortion_model == 'plumb_bob'


@pytest.mark.parametrize(
    ('edit', 'match'),
    [
        (('distortion_model: plumb_bob', 'distortion_model: kannala_brandt_x'),
         'kannala_brandt_x'),
        (('data: [1203.5, 0, 641.25, 0, 1204.25, 509.75, 0, 0, 1]',
          'data: [0, 0, 0, 0, 0, 0, 0, 0, 0]'), 'K must be'),
        (('image_width: 1280\n', ''), 'image_width: must be a positive integer'),
        (('  rows: 3\n  cols: 3\n  data: [1203.5', '  rows: 2\n  cols: 3\n  data: [1203.5'),
         'camera_matrix: must be 3 x 3'),
        (('data: [-0.081, 0.021, 0.0004, -0.0003, 0]', 'data: [-0.081, x]'),
         'distortion_coefficients: data must be 5 numbers'),
        (('image_width: 1280', 'image_width: [1280'), 'not a YAML calibration file'),
    ],
)  # fmt: skip
def test_bad_files_are_one_line_naming_the_file(tmp_path, edit, match):
    path = tmp_path / 'cam.yaml'
    assert edit[0] in CALIBRATOR_OUTPUT
    path.write_text(CALIBRATOR_OUTPUT.replace(*edit))
    with pytest.raises(ConfigError, match=match) as error:
        read_camera_info_file(path)
    assert str(error.value).startswith(str(path)) and '\n' not in str(error.value)


@pytest.mark.parametrize(
    ('url', 'match'),
    [
        ('package://lumpbeam_ros/config/cam.yaml', r'unsupported URL scheme package://'),
        ('file://host/cam.yaml', 'absolute path'),
        ('file:///nonexistent/cam.yaml', 'cannot read the calibration file'),
    ],
)
def test_bad_urls(url, match):
    with pytest.raises(ConfigError, match=match):
        camera_info_from_url(url)
