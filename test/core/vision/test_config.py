from pathlib import Path

import numpy as np
import pytest
import yaml

from lumpbeam_ros.base.errors import ConfigError
from lumpbeam_ros.base.resources import config_path
from lumpbeam_ros.core.vision.config import load_camera_config


def test_default_file_loads_with_documented_values():
    config = load_camera_config()
    assert (config.camera_info.width, config.camera_info.height) == (2048, 2048)
    assert config.camera_info.k[0, 0] == 2400.0
    assert config.rig.board.pattern_size == (8, 6)
    assert config.rig.board.square_size_m == 0.06
    assert config.synthetic.exposure_s == 0.001
    # The camera looks along +y of the tip: its optical axis is the tip's y axis.
    np.testing.assert_allclose(config.rig.tip_camera.rotation[:, 2], [0, 1, 0], atol=1e-12)


def _write(tmp_path: Path, change: dict) -> Path:
    document = yaml.safe_load(config_path('camera.yaml').read_text())
    params = document['/**']['ros__parameters']
    for dotted, value in change.items():
        *parents, leaf = dotted.split('.')
        node = params
        for name in parents:
            node = node[name]
        node[leaf] = value
    path = tmp_path / 'camera.yaml'
    path.write_text(yaml.safe_dump(document))
    return path


@pytest.mark.parametrize(
    ('change', 'key'),
    [
        ({'camera.focal_length_px': -5.0}, 'camera.focal_length_px'),
        ({'camera.width_px': 'wide'}, 'camera.width_px'),
        ({'camera.distortion': [0.1, 0.0]}, 'camera.distortion'),
        ({'camera.mount.rpy_rad': [0.0, 'x', 0.0]}, 'camera.mount.rpy_rad'),
        ({'board.square_size_m': 0.0}, 'board.square_size_m'),
        ({'board.squares_y': 9}, 'board.squares_y'),
        ({'board.squares_x': 2}, 'board.squares_x'),
        ({'synthetic.noise_sigma_dn': -1.0}, 'synthetic.noise_sigma_dn'),
        ({'synthetic.light_dn': 20.0}, 'synthetic.light_dn'),
        ({'synthetic.wall_dn': 300.0}, 'synthetic.wall_dn'),
        ({'tracker.window_fraction': 0.6}, 'tracker.window_fraction'),
        ({'tracker.calibration_frames': 2}, 'tracker.calibration_frames'),
        ({'tracker.max_window_px': 2}, 'tracker.max_window_px'),
        ({'tracker.max_window_px': 12.5}, 'tracker.max_window_px'),
        ({'tracker.max_depth_correction': 0.0}, 'tracker.max_depth_correction'),
        ({'tracker.max_depth_correction': 'many'}, 'tracker.max_depth_correction'),
        ({'tracker.typo_key': 1}, 'tracker.typo_key'),
    ],
)
def test_bad_values_name_file_and_key(tmp_path, change, key):
    path = _write(tmp_path, change)
    with pytest.raises(ConfigError) as info:
        load_camera_config(path)
    assert info.value.key == key
    assert str(path) in str(info.value)


def test_missing_and_non_parameter_files(tmp_path):
    with pytest.raises(ConfigError, match='no such file'):
        load_camera_config(tmp_path / 'absent.yaml')
    path = tmp_path / 'plain.yaml'
    path.write_text('camera: {width_px: 3}\n')
    with pytest.raises(ConfigError, match='ros__parameters'):
        load_camera_config(path)
