import pytest

from lumpbeam_ros.base.errors import ConfigError
from lumpbeam_ros.base.interface import BASE_FRAME, CAMERA_INFO, CAMERA_NODE, IMAGE
from lumpbeam_ros.base.paramfile import read_parameter_file
from lumpbeam_ros.base.resources import config_path
from lumpbeam_ros.core.vision.config import (
    CAMERA_SETTINGS,
    camera_config_from_parameters,
    load_camera_config,
)
from lumpbeam_ros.core.vision.free_pose import POSE_MODELS
from lumpbeam_ros.nodes.params.camera_params import CAMERA_SCHEMA, CONFIG_KEYS


def test_camera_schema_is_the_camera_config():
    names = {spec.name for spec in CAMERA_SETTINGS}
    assert names == set(read_parameter_file(config_path('camera.yaml')))
    assert names == set(CONFIG_KEYS) | {spec.name for spec in CAMERA_SCHEMA.file_only}
    defaults = CAMERA_SCHEMA.defaults()
    config = camera_config_from_parameters({k: defaults[k] for k in CONFIG_KEYS}, 'schema')
    assert repr(config) == repr(load_camera_config())  # numpy fields: no ==


def test_the_node_declares_no_synthetic_camera_parameter():
    # The synthetic camera renders lumpbeam synth's images; the node never reads it.
    assert not any(name.startswith('synthetic.') for name in CAMERA_SCHEMA.names)
    assert all(spec.name.startswith('synthetic.') for spec in CAMERA_SCHEMA.file_only)


def test_the_node_parameters_follow_the_config_keys():
    assert CAMERA_SCHEMA.node == CAMERA_NODE
    assert CAMERA_SCHEMA.names[: len(CONFIG_KEYS)] == list(CONFIG_KEYS)
    node_only = CAMERA_SCHEMA.names[len(CONFIG_KEYS) :]
    assert node_only and not any('.' in name for name in node_only)
    assert all(spec.read_only for spec in CAMERA_SCHEMA)  # the summary says so
    defaults = CAMERA_SCHEMA.defaults()
    assert defaults['frame_id'] == BASE_FRAME
    assert (defaults['bag_image_topic'], defaults['bag_camera_info_topic']) == (IMAGE, CAMERA_INFO)
    assert CAMERA_SCHEMA['pose_model'].choices == POSE_MODELS


@pytest.mark.parametrize(
    ('name', 'length'),
    [
        ('camera.distortion', 5),  # plumb_bob: k1, k2, p1, p2, k3 (sensor_msgs/CameraInfo)
        ('camera.principal_point_offset_px', 2),
        ('camera.mount.xyz_m', 3),
    ],
)
def test_vectors_have_their_geometric_length(name, length):
    spec = CAMERA_SCHEMA[name]
    assert spec.kind == 'double[]' and spec.length == length
    assert CAMERA_SCHEMA.problem(name, [0.0] * (length + 1)) is not None
    assert CAMERA_SCHEMA.problem(name, [0.0] * length) is None


@pytest.mark.parametrize(
    ('values', 'key', 'message'),
    [
        ({'board.squares_x': 7, 'board.squares_y': 7}, 'board.squares_y', 'differ'),
        ({'synthetic.dark_dn': 200.0, 'synthetic.light_dn': 150.0}, 'light_dn', 'brighter'),
        ({'synthetic.dark_dn': 150.0, 'synthetic.light_dn': 150.0}, 'light_dn', 'brighter'),
        ({'tracker.calibration_frames': 2}, 'calibration_frames', '0 or at least 3'),
    ],
)
def test_what_one_value_cannot_show_is_refused_by_the_configuration(values, key, message):
    # Each value alone is one the schema accepts; together they describe no camera.
    specs = {spec.name: spec for spec in CAMERA_SETTINGS}
    assert all(specs[k].problem(v) is None for k, v in values.items())
    with pytest.raises(ConfigError, match=f'{key}.*{message}'):
        camera_config_from_parameters(values, 'probe')


@pytest.mark.parametrize(
    ('name', 'value', 'problem'),
    [
        ('camera.width_px', 32, 'at least 64'),
        ('camera.focal_length_px', 0.0, 'positive'),
        ('camera.distortion', [0.0] * 4, 'a list of 5 finite numbers'),
        ('pose_model', 'sphere', 'one of plane, free'),
        ('frame_id', 3, 'must be a string'),
        ('use_config_camera_info', 'yes', 'true or false'),
    ],
)
def test_bad_values_are_named(name, value, problem):
    assert problem in CAMERA_SCHEMA.problem(name, value)
    assert CAMERA_SCHEMA.problem(name, value).startswith(f'{name}: ')
