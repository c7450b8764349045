"""The camera configuration (``config/camera.yaml``): dataclasses and a validating loader."""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from lumpbeam_ros.errors import ConfigError, LumpbeamError
from lumpbeam_ros.paramfile import check_known_keys, get_float, get_int, read_parameter_file
from lumpbeam_ros.resources import config_path
from lumpbeam_ros.vision.board import Checkerboard
from lumpbeam_ros.vision.camera_model import CameraInfo
from lumpbeam_ros.vision.geometry import Transform


@dataclass(frozen=True)
class RigGeometry:
    """Where the camera and the board are.

    Attributes:
        board: The checkerboard.
        tip_camera: The camera optical frame in the tip frame (``T_tip_camera``).
        base_board: The board frame in ``beam_base`` (``T_base_board``).
    """

    board: Checkerboard
    tip_camera: Transform
    base_board: Transform


@dataclass(frozen=True)
class SyntheticSettings:
    """How the synthetic camera renders (see ``config/camera.yaml`` for each field)."""

    exposure_s: float = 0.001
    noise_sigma_dn: float = 2.0
    defocus_sigma_px: float = 0.8
    dark_dn: float = 30.0
    light_dn: float = 220.0
    wall_dn: float = 110.0
    supersample: int = 2
    motion_step_px: float = 0.5
    max_motion_samples: int = 16
    seed: int = 1


@dataclass(frozen=True)
class TrackerSettings:
    """How the tracker detects, verifies and calibrates (see ``config/camera.yaml``)."""

    detect_max_side_px: int = 640
    window_fraction: float = 0.2
    max_homography_residual_px: float = 1.0
    max_rms_px: float = 0.5
    min_contrast_dn: float = 20.0
    max_saturated_fraction: float = 0.2
    calibration_frames: int = 30
    calibration_min_step_m: float = 0.001
    min_corners: int = 12
    min_corner_spread: float = 0.5
    tilt_prior_std_rad: float = 5.0e-6


@dataclass(frozen=True)
class CameraConfig:
    """Everything in ``config/camera.yaml``.

    Attributes:
        camera_info: Intrinsics and image size.
        rig: Camera mount and board pose.
        synthetic: Rendering settings of the synthetic camera.
        tracker: Tracker settings.
    """

    camera_info: CameraInfo
    rig: RigGeometry
    synthetic: SyntheticSettings = field(default_factory=SyntheticSettings)
    tracker: TrackerSettings = field(default_factory=TrackerSettings)

    def with_resolution(self, width: int, height: int) -> CameraConfig:
        """Returns the same set-up on a sensor of another size (same horizontal view)."""
        return replace(self, camera_info=self.camera_info.scaled(width, height))


_KEYS = frozenset(
    {
        'camera.width_px',
        'camera.height_px',
        'camera.focal_length_px',
        'camera.principal_point_offset_px',
        'camera.distortion',
        'camera.mount.xyz_m',
        'camera.mount.rpy_rad',
        'board.squares_x',
        'board.squares_y',
        'board.square_size_m',
        'board.margin_squares',
        'board.xyz_m',
        'board.rpy_rad',
    }
    | {f'synthetic.{name}' for name in SyntheticSettings.__dataclass_fields__}
    | {f'tracker.{name}' for name in TrackerSettings.__dataclass_fields__}
)


def _get_vector(
    params: Mapping[str, Any], key: str, source: str | Path, default: tuple[float, ...]
) -> tuple[float, ...]:
    if key not in params:
        return default
    value = params[key]
    if (
        not isinstance(value, list | tuple)
        or len(value) != len(default)
        or any(isinstance(v, bool) or not isinstance(v, int | float) for v in value)
        or not np.all(np.isfinite(np.asarray(value, dtype=float)))
    ):
        raise ConfigError(
            source, key, f'must be a list of {len(default)} finite numbers, got {value!r}'
        )
    return tuple(float(v) for v in value)


def camera_config_from_parameters(params: Mapping[str, Any], source: str | Path) -> CameraConfig:
    """Builds and validates the camera configuration from flat (dotted) ROS parameters.

    Missing keys take the defaults documented in ``config/camera.yaml``.

    Args:
        params: Flat parameters, e.g. from :func:`~lumpbeam_ros.paramfile.read_parameter_file`.
        source: Where they came from, for error messages.

    Returns:
        The configuration.

    Raises:
        ConfigError: An unknown key, a wrong type or an out-of-range value.
    """
    check_known_keys(params, _KEYS, source)
    pos = {'positive': True}
    nonneg = {'non_negative': True}
    half_pi = np.pi / 2.0
    width = get_int(params, 'camera.width_px', source, 2048, minimum=64)
    height = get_int(params, 'camera.height_px', source, 2048, minimum=64)
    focal = get_float(params, 'camera.focal_length_px', source, 2400.0, **pos)
    offset = _get_vector(params, 'camera.principal_point_offset_px', source, (0.0, 0.0))
    distortion = _get_vector(params, 'camera.distortion', source, (0.0,) * 5)
    camera_info = CameraInfo.pinhole(width, height, focal, offset, distortion)  # type: ignore[arg-type]
    board = Checkerboard(
        squares_x=get_int(params, 'board.squares_x', source, 9, minimum=3),
        squares_y=get_int(params, 'board.squares_y', source, 7, minimum=3),
        square_size_m=get_float(params, 'board.square_size_m', source, 0.06, **pos),
        margin_squares=get_float(params, 'board.margin_squares', source, 1.0, positive=True),
    )
    if board.squares_x == board.squares_y:
        # A square pattern can be detected transposed; a rectangular one fixes which way
        # the rows run, and the expected orientation then fixes where they start.
        raise ConfigError(source, 'board.squares_y', 'must differ from squares_x')
    rig = RigGeometry(
        board=board,
        tip_camera=Transform.from_xyz_rpy(
            _get_vector(params, 'camera.mount.xyz_m', source, (0.0, 0.05, 0.0)),  # type: ignore[arg-type]
            _get_vector(params, 'camera.mount.rpy_rad', source, (-half_pi, 0.0, 0.0)),  # type: ignore[arg-type]
        ),
        base_board=Transform.from_xyz_rpy(
            _get_vector(params, 'board.xyz_m', source, (2.3107, 1.0, -0.01)),  # type: ignore[arg-type]
            _get_vector(params, 'board.rpy_rad', source, (-half_pi, 0.0, 0.0)),  # type: ignore[arg-type]
        ),
    )
    s = SyntheticSettings()
    synthetic = SyntheticSettings(
        exposure_s=get_float(params, 'synthetic.exposure_s', source, s.exposure_s, **nonneg),
        noise_sigma_dn=get_float(
            params, 'synthetic.noise_sigma_dn', source, s.noise_sigma_dn, **nonneg
        ),
        defocus_sigma_px=get_float(
            params, 'synthetic.defocus_sigma_px', source, s.defocus_sigma_px, **nonneg
        ),
        dark_dn=get_float(params, 'synthetic.dark_dn', source, s.dark_dn, **nonneg),
        light_dn=get_float(params, 'synthetic.light_dn', source, s.light_dn, **nonneg),
        wall_dn=get_float(params, 'synthetic.wall_dn', source, s.wall_dn, **nonneg),
        supersample=get_int(params, 'synthetic.supersample', source, s.supersample, minimum=1),
        motion_step_px=get_float(
            params, 'synthetic.motion_step_px', source, s.motion_step_px, **pos
        ),
        max_motion_samples=get_int(
            params, 'synthetic.max_motion_samples', source, s.max_motion_samples, minimum=1
        ),
        seed=get_int(params, 'synthetic.seed', source, s.seed, minimum=0),
    )
    for key in ('dark_dn', 'light_dn', 'wall_dn'):
        if getattr(synthetic, key) > 255.0:
            raise ConfigError(source, f'synthetic.{key}', 'must be at most 255 (mono8)')
    if synthetic.light_dn <= synthetic.dark_dn:
        raise ConfigError(source, 'synthetic.light_dn', 'must be brighter than dark_dn')
    t = TrackerSettings()
    tracker = TrackerSettings(
        detect_max_side_px=get_int(
            params, 'tracker.detect_max_side_px', source, t.detect_max_side_px, minimum=160
        ),
        window_fraction=get_float(
            params, 'tracker.window_fraction', source, t.window_fraction, **pos
        ),
        max_homography_residual_px=get_float(
            params,
            'tracker.max_homography_residual_px',
            source,
            t.max_homography_residual_px,
            **pos,
        ),
        max_rms_px=get_float(params, 'tracker.max_rms_px', source, t.max_rms_px, **pos),
        min_contrast_dn=get_float(
            params, 'tracker.min_contrast_dn', source, t.min_contrast_dn, **nonneg
        ),
        max_saturated_fraction=get_float(
            params, 'tracker.max_saturated_fraction', source, t.max_saturated_fraction, **pos
        ),
        calibration_frames=get_int(
            params, 'tracker.calibration_frames', source, t.calibration_frames, minimum=0
        ),
        calibration_min_step_m=get_float(
            params,
            'tracker.calibration_min_step_m',
            source,
            t.calibration_min_step_m,
            non_negative=True,
        ),
        tilt_prior_std_rad=get_float(
            params, 'tracker.tilt_prior_std_rad', source, t.tilt_prior_std_rad, **pos
        ),
    )
    tracker = replace(
        tracker,
        min_corners=get_int(params, 'tracker.min_corners', source, t.min_corners, minimum=6),
        min_corner_spread=get_float(
            params, 'tracker.min_corner_spread', source, t.min_corner_spread, positive=True
        ),
    )
    if tracker.window_fraction >= 0.5:
        # A window reaching the neighbouring corner pulls the estimate toward it.
        raise ConfigError(source, 'tracker.window_fraction', 'must be below 0.5')
    if 0 < tracker.calibration_frames < 3:
        raise ConfigError(source, 'tracker.calibration_frames', 'must be 0 or at least 3')
    return CameraConfig(camera_info, rig, synthetic, tracker)


def load_camera_config(path: str | Path | None = None) -> CameraConfig:
    """Reads a camera parameter file (default: the package's ``config/camera.yaml``).

    Args:
        path: The YAML file, or ``None`` for the default.

    Returns:
        The configuration.

    Raises:
        ConfigError: The file is missing or malformed, or a value is invalid.
    """
    path = config_path('camera.yaml') if path is None else Path(path)
    return camera_config_from_parameters(read_parameter_file(path), path)


def parse_board(text: str) -> tuple[int, int]:
    """Parses ``COLSxROWS``, the board's inner corners (e.g. ``8x6`` for 9 x 7 squares).

    Raises:
        LumpbeamError: Not two integers joined by ``x``, fewer than 2 either way, or a
            square pattern (its orientation would be ambiguous).
    """
    match = re.fullmatch(r'\s*(\d+)\s*[xX]\s*(\d+)\s*', text)
    if match is None:
        raise LumpbeamError(f'--board {text!r}: expected COLSxROWS inner corners, e.g. 8x6')
    cols, rows = int(match.group(1)), int(match.group(2))
    if min(cols, rows) < 2:
        raise LumpbeamError(f'--board {text!r}: need at least 2 inner corners each way')
    if cols == rows:
        raise LumpbeamError(f'--board {text!r}: columns and rows must differ')
    return cols, rows


def with_board(
    config: CameraConfig,
    inner_corners: tuple[int, int] | None = None,
    square_size_m: float | None = None,
) -> CameraConfig:
    """Returns the configuration with another checkerboard (the rest of the rig unchanged).

    Args:
        config: The configuration.
        inner_corners: ``(columns, rows)`` of inner corners (see :func:`parse_board`), or
            ``None`` to keep the configured pattern.
        square_size_m: The edge of one square, m, or ``None`` to keep it.

    Returns:
        The configuration.

    Raises:
        LumpbeamError: A square size that is not a positive finite number.
    """
    board = config.rig.board
    if inner_corners is not None:
        board = replace(board, squares_x=inner_corners[0] + 1, squares_y=inner_corners[1] + 1)
    if square_size_m is not None:
        if not (math.isfinite(square_size_m) and square_size_m > 0):
            raise LumpbeamError(f'--square-m {square_size_m!r}: must be a positive length, m')
        board = replace(board, square_size_m=float(square_size_m))
    return replace(config, rig=replace(config.rig, board=board))
