"""The camera node's parameters: its camera configuration (``config/camera.yaml``) and its own.

The ``camera.*``, ``board.*`` and ``tracker.*`` parameters are the fields of
:mod:`lumpbeam_ros.core.vision.config`'s sections, each declared there once. The file's
``synthetic.*`` section is read by ``lumpbeam synth``, not by the node, which does not declare it.
"""

from __future__ import annotations

from lumpbeam_ros.base.interface import BASE_FRAME, CAMERA_INFO, CAMERA_NODE, IMAGE
from lumpbeam_ros.base.schema import Bounds, ParameterSchema, ParameterSpec, settings_specs
from lumpbeam_ros.core.vision.config import (
    BoardSettings,
    SensorSettings,
    SyntheticSettings,
    TrackerSettings,
)
from lumpbeam_ros.core.vision.free_pose import POSE_MODELS
from lumpbeam_ros.nodes.realtime import REALTIME_PRIORITY

_POSITIVE = Bounds(0.0, low_open=True)
_NON_NEGATIVE = Bounds(0.0)


def _double(
    name: str, default: float, description: str, unit: str = '', bounds: Bounds = _POSITIVE
) -> ParameterSpec:
    return ParameterSpec(name, 'double', default, description, unit, bounds)


_NODE = (
    ParameterSpec('frame_id', 'string', BASE_FRAME, 'header.frame_id of the published poses'),
    REALTIME_PRIORITY,
    ParameterSpec(
        'bag_path',
        'string',
        '',
        'read frames from this bag in-process instead of subscribing (empty: off)',
    ),
    ParameterSpec('bag_image_topic', 'string', IMAGE, 'image topic read from bag_path'),
    ParameterSpec(
        'bag_camera_info_topic',
        'string',
        CAMERA_INFO,
        'camera info topic read from bag_path',
    ),
    ParameterSpec(
        'use_config_camera_info',
        'bool',
        False,
        'track with the intrinsics of the camera.* parameters, without waiting for camera_info',
    ),
    ParameterSpec(
        'camera_info_url',
        'string',
        '',
        'ROS camera calibration YAML as file:///path.yaml: the intrinsics, without waiting '
        'for camera_info (empty: off)',
    ),
    ParameterSpec(
        'footage_path',
        'string',
        '',
        'read frames from this video file or image folder in-process (empty: off)',
    ),
    _double(
        'footage_fps',
        0.0,
        'frame rate stamping footage_path: t_i = footage_start_time_s + i / fps (0: off)',
        'Hz',
        _NON_NEGATIVE,
    ),
    ParameterSpec(
        'footage_start_time_s',
        'double',
        0.0,
        'stamp of the first frame of footage_path with footage_fps',
        's',
    ),
    ParameterSpec(
        'footage_timestamps',
        'string',
        '',
        'timestamps file of footage_path instead of footage_fps: one stamp per line, s',
    ),
    ParameterSpec(
        'video_device',
        'string',
        '',
        'read a live camera through OpenCV: device index (0), device path or URL; frames are '
        'stamped with the node clock on arrival (empty: off)',
    ),
    ParameterSpec(
        'pose_model',
        'string',
        'plane',
        'plane: x, z, pitch in the plane of bending; free: the full 6-DoF pose (with identity '
        "extrinsics, the camera's pose in the board's frame)",
        choices=POSE_MODELS,
    ),
    _double(
        'wait_for_subscriber_s',
        5.0,
        'with bag_path or footage_path: wait at most this long for a /tip_pose subscriber '
        'before the first frame, and for reliable subscribers to acknowledge the last poses '
        'before exiting (0: neither)',
        's',
        _NON_NEGATIVE,
    ),
    _double('diagnostics_period_s', 1.0, 'period of /diagnostics', 's'),
    _double(
        'warning_period_s',
        2.0,
        'at most one warning of each kind (camera_info, no pose, footage) in this period',
        's',
        _NON_NEGATIVE,
    ),
)

#: The camera configuration's parameters the node declares (config/camera.yaml's but
#: ``synthetic.*``).
CONFIG_KEYS = tuple(
    spec.name
    for section in (SensorSettings, BoardSettings, TrackerSettings)
    for spec in settings_specs(section)
)

CAMERA_SCHEMA = ParameterSchema(
    node=CAMERA_NODE,
    summary=(
        'Camera frames in, the tip pose out. The `camera.*`, `board.*` and `tracker.*` values '
        'are those of config/camera.yaml (its `synthetic.*` section is read by '
        '`lumpbeam synth`, not by the node). Every parameter is read-only: set it in the '
        'params file or with -p.'
    ),
    config_file='camera.yaml',
    file_only=settings_specs(SyntheticSettings),
    parameters=(
        *(
            spec
            for section in (SensorSettings, BoardSettings, TrackerSettings)
            for spec in settings_specs(section)
        ),
        *_NODE,
    ),
)
