"""The camera node's parameters: ``config/camera.yaml`` (documented there) and the node's own.

The ``camera.*``, ``board.*``, ``synthetic.*`` and ``tracker.*`` values are the defaults of
:func:`~lumpbeam_ros.vision.config.camera_config_from_parameters`, which also checks what a
single value cannot (``board.squares_y`` differs from ``squares_x``, ``light_dn`` above
``dark_dn``, ``tracker.calibration_frames`` 0 or at least 3); a test holds the schema, the
file and that function in agreement.
"""

from __future__ import annotations

import math

from lumpbeam_ros.interface import BASE_FRAME, CAMERA_INFO, CAMERA_NODE, IMAGE
from lumpbeam_ros.params.schema import Bounds, ParameterSchema, ParameterSpec
from lumpbeam_ros.vision.free_pose import POSE_MODELS

_POSITIVE = Bounds(0.0, low_open=True)
_NON_NEGATIVE = Bounds(0.0)
_GREY = Bounds(0.0, 255.0)
_HALF_PI = math.pi / 2.0


def _vector(name: str, default: tuple[float, ...], description: str, unit: str) -> ParameterSpec:
    return ParameterSpec(name, 'double[]', default, description, unit, length=len(default))


def _double(
    name: str, default: float, description: str, unit: str = '', bounds: Bounds = _POSITIVE
) -> ParameterSpec:
    return ParameterSpec(name, 'double', default, description, unit, bounds)


def _int(name: str, default: int, description: str, minimum: int, unit: str = '') -> ParameterSpec:
    return ParameterSpec(name, 'int', default, description, unit, Bounds(minimum))


_CAMERA = (
    _int('camera.width_px', 2048, 'sensor width; checked against each image', 64, 'px'),
    _int('camera.height_px', 2048, 'sensor height; checked against each image', 64, 'px'),
    _double('camera.focal_length_px', 2400.0, 'focal length, fx = fy', 'px'),
    _vector(
        'camera.principal_point_offset_px',
        (0.0, 0.0),
        'principal point minus the image centre ((width - 1) / 2, (height - 1) / 2)',
        'px',
    ),
    _vector(
        'camera.distortion',
        (0.0,) * 5,
        'plumb_bob distortion k1, k2, p1, p2, k3 (all zero: an ideal pinhole)',
        '',
    ),
    _vector(
        'camera.mount.xyz_m',
        (0.0, 0.05, 0.0),
        "origin of the camera's optical frame in the tip frame",
        'm',
    ),
    _vector(
        'camera.mount.rpy_rad',
        (-_HALF_PI, 0.0, 0.0),
        "roll-pitch-yaw of the camera's optical frame in the tip frame (URDF convention)",
        'rad',
    ),
)

_BOARD = (
    _int('board.squares_x', 9, 'squares along the board x axis (differs from squares_y)', 3),
    _int('board.squares_y', 7, 'squares along the board y axis (differs from squares_x)', 3),
    _double('board.square_size_m', 0.06, 'edge of one square', 'm'),
    _double('board.margin_squares', 1.0, 'white border around the squares', 'squares'),
    _vector('board.xyz_m', (2.3107, 1.0, -0.01), 'position of the board frame in beam_base', 'm'),
    _vector(
        'board.rpy_rad',
        (-_HALF_PI, 0.0, 0.0),
        'roll-pitch-yaw of the board frame in beam_base',
        'rad',
    ),
)

_SYNTHETIC = (
    _double(
        'synthetic.exposure_s',
        0.001,
        'exposure time of the synthetic camera (motion blur); a stamp is its middle',
        's',
        _NON_NEGATIVE,
    ),
    _double(
        'synthetic.noise_sigma_dn',
        2.0,
        'standard deviation of additive Gaussian sensor noise',
        'DN',
        _NON_NEGATIVE,
    ),
    _double(
        'synthetic.defocus_sigma_px',
        0.8,
        'standard deviation of a Gaussian defocus blur',
        'px',
        _NON_NEGATIVE,
    ),
    _double('synthetic.dark_dn', 30.0, 'grey level of the dark squares', 'DN', _GREY),
    _double(
        'synthetic.light_dn', 220.0, 'grey level of the light squares (above dark_dn)', 'DN', _GREY
    ),
    _double('synthetic.wall_dn', 110.0, 'grey level of the wall', 'DN', _GREY),
    _int('synthetic.supersample', 2, 'render at this many times the resolution, average down', 1),
    _double(
        'synthetic.motion_step_px',
        0.5,
        'motion blur: most a board point moves between two sub-poses of an exposure',
        'px',
    ),
    _int('synthetic.max_motion_samples', 16, 'motion blur: most sub-poses per exposure', 1),
    _int('synthetic.seed', 1, 'seed of the noise generator', 0),
)

_TRACKER = (
    _int(
        'tracker.detect_max_side_px',
        640,
        'full detection runs on a copy shrunk to at most this longer side',
        160,
        'px',
    ),
    _double(
        'tracker.window_fraction',
        0.2,
        "corner refinement window half-size, as a fraction of a square's size in pixels",
        bounds=Bounds(0.0, 0.5, low_open=True, high_open=True),
    ),
    _double(
        'tracker.max_homography_residual_px',
        1.0,
        'a frame is rejected when a homography through its corners misses one by more',
        'px',
    ),
    _double(
        'tracker.max_rms_px',
        0.5,
        'a pose is rejected when the RMS reprojection error of its fit exceeds this',
        'px',
    ),
    _double(
        'tracker.min_contrast_dn',
        20.0,
        'a frame is too dark when its 1st to 99th percentile spread is below this',
        'DN',
        _NON_NEGATIVE,
    ),
    _double(
        'tracker.max_saturated_fraction',
        0.2,
        'a frame is saturated when more than this fraction of its pixels is at 255',
    ),
    ParameterSpec(
        'tracker.calibration_frames',
        'int',
        30,
        'good frames that estimate the camera distance and tilt before the refined extrinsics '
        'are used; 0 trusts the configured rig, else at least 3',
        bounds=Bounds(0),
    ),
    _double(
        'tracker.calibration_min_step_m',
        0.001,
        'a good frame joins the calibration only if the tip moved this far since the last one',
        'm',
        _NON_NEGATIVE,
    ),
    _int(
        'tracker.min_corners',
        12,
        'a partial view gives a pose from at least this many corners',
        6,
    ),
    _double(
        'tracker.min_corner_spread',
        0.5,
        "a partial view's corners spread at least this far (rms) across their weakest direction",
        'squares',
    ),
    _double(
        'tracker.tilt_prior_std_rad',
        5.0e-6,
        "how well the mount's out-of-plane tilt (camera.mount.rpy_rad) is known: the rig "
        'calibration fits the tilt with this Gaussian prior',
        'rad',
    ),
)

_NODE = (
    ParameterSpec('frame_id', 'string', BASE_FRAME, 'header.frame_id of the published poses'),
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
    _double('diagnostics_period_s', 1.0, 'period of /diagnostics', 's'),
    _double(
        'warning_period_s',
        2.0,
        'at most one warning of each kind (camera_info, no pose, footage) in this period',
        's',
        _NON_NEGATIVE,
    ),
)

#: The parameters of ``config/camera.yaml`` (the camera configuration's keys).
CONFIG_KEYS = tuple(spec.name for spec in (*_CAMERA, *_BOARD, *_SYNTHETIC, *_TRACKER))

CAMERA_SCHEMA = ParameterSchema(
    node=CAMERA_NODE,
    summary=(
        'Camera frames in, the tip pose out. The `camera.*`, `board.*`, `synthetic.*` and '
        '`tracker.*` values are those of config/camera.yaml (`synthetic.*` is read by '
        '`lumpbeam synth`, not by the node). Every parameter is read-only: set it in the '
        'params file or with -p.'
    ),
    config_file='camera.yaml',
    parameters=(*_CAMERA, *_BOARD, *_SYNTHETIC, *_TRACKER, *_NODE),
)
