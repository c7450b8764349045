"""The camera configuration (``config/camera.yaml``): its sections, each field a parameter.

Each field of the four sections is declared once, with :func:`~lumpbeam_ros.base.schema.
setting`; the camera node's parameters (:mod:`lumpbeam_ros.nodes.params.camera_params`), the checks
of a parameter file and ``doc/parameters.md`` come from them.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.paramfile import check_known_keys, parameter_file
from lumpbeam_ros.base.schema import Bounds, setting, settings_from_parameters, settings_specs
from lumpbeam_ros.core.vision.board import Checkerboard
from lumpbeam_ros.core.vision.camera_model import CameraInfo
from lumpbeam_ros.core.vision.geometry import Transform


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


_POSITIVE = Bounds(0.0, low_open=True)
_NON_NEGATIVE = Bounds(0.0)
_GREY = Bounds(0.0, 255.0)
_HALF_PI = math.pi / 2.0


@dataclass(frozen=True)
class SensorSettings:
    """The camera's intrinsics and its mount on the tip (``camera.*``)."""

    width_px: int = setting(
        'camera.width_px', 2048, 'sensor width; checked against each image', 'px', Bounds(64)
    )
    height_px: int = setting(
        'camera.height_px', 2048, 'sensor height; checked against each image', 'px', Bounds(64)
    )
    focal_length_px: float = setting(
        'camera.focal_length_px', 2400.0, 'focal length, fx = fy', 'px', _POSITIVE
    )
    principal_point_offset_px: tuple[float, float] = setting(
        'camera.principal_point_offset_px',
        (0.0, 0.0),
        'principal point minus the image centre ((width - 1) / 2, (height - 1) / 2)',
        'px',
    )
    distortion: tuple[float, float, float, float, float] = setting(
        'camera.distortion',
        (0.0, 0.0, 0.0, 0.0, 0.0),
        'plumb_bob distortion k1, k2, p1, p2, k3 (all zero: an ideal pinhole)',
    )
    mount_xyz_m: tuple[float, float, float] = setting(
        'camera.mount.xyz_m',
        (0.0, 0.05, 0.0),
        "origin of the camera's optical frame in the tip frame",
        'm',
    )
    mount_rpy_rad: tuple[float, float, float] = setting(
        'camera.mount.rpy_rad',
        (-_HALF_PI, 0.0, 0.0),
        "roll-pitch-yaw of the camera's optical frame in the tip frame (URDF convention)",
        'rad',
    )


@dataclass(frozen=True)
class BoardSettings:
    """The checkerboard and where it stands (``board.*``)."""

    squares_x: int = setting(
        'board.squares_x',
        9,
        'squares along the board x axis (differs from squares_y)',
        bounds=Bounds(3),
    )
    squares_y: int = setting(
        'board.squares_y',
        7,
        'squares along the board y axis (differs from squares_x)',
        bounds=Bounds(3),
    )
    square_size_m: float = setting(
        'board.square_size_m', 0.06, 'edge of one square', 'm', _POSITIVE
    )
    margin_squares: float = setting(
        'board.margin_squares', 1.0, 'white border around the squares', 'squares', _POSITIVE
    )
    xyz_m: tuple[float, float, float] = setting(
        'board.xyz_m', (2.3107, 1.0, -0.01), 'position of the board frame in beam_base', 'm'
    )
    rpy_rad: tuple[float, float, float] = setting(
        'board.rpy_rad',
        (-_HALF_PI, 0.0, 0.0),
        'roll-pitch-yaw of the board frame in beam_base',
        'rad',
    )

    def relation_problem(self) -> tuple[str, str] | None:
        """What the values break together: ``(key, problem)``, or ``None``."""
        if self.squares_x == self.squares_y:
            # A square pattern can be detected transposed; a rectangular one fixes which way
            # the rows run, and the expected orientation then fixes where they start.
            return 'board.squares_y', 'must differ from squares_x'
        return None


@dataclass(frozen=True)
class SyntheticSettings:
    """How the synthetic camera of ``lumpbeam synth`` renders (``synthetic.*``)."""

    exposure_s: float = setting(
        'synthetic.exposure_s',
        0.001,
        'exposure time of the synthetic camera (motion blur); a stamp is its middle',
        's',
        _NON_NEGATIVE,
    )
    noise_sigma_dn: float = setting(
        'synthetic.noise_sigma_dn',
        2.0,
        'standard deviation of additive Gaussian sensor noise',
        'DN',
        _NON_NEGATIVE,
    )
    defocus_sigma_px: float = setting(
        'synthetic.defocus_sigma_px',
        0.8,
        'standard deviation of a Gaussian defocus blur',
        'px',
        _NON_NEGATIVE,
    )
    dark_dn: float = setting(
        'synthetic.dark_dn', 30.0, 'grey level of the dark squares', 'DN', _GREY
    )
    light_dn: float = setting(
        'synthetic.light_dn', 220.0, 'grey level of the light squares (above dark_dn)', 'DN', _GREY
    )
    wall_dn: float = setting('synthetic.wall_dn', 110.0, 'grey level of the wall', 'DN', _GREY)
    supersample: int = setting(
        'synthetic.supersample',
        2,
        'render at this many times the resolution, average down',
        bounds=Bounds(1),
    )
    motion_step_px: float = setting(
        'synthetic.motion_step_px',
        0.5,
        'motion blur: most a board point moves between two sub-poses of an exposure',
        'px',
        _POSITIVE,
    )
    max_motion_samples: int = setting(
        'synthetic.max_motion_samples',
        16,
        'motion blur: most sub-poses per exposure',
        bounds=Bounds(1),
    )
    seed: int = setting('synthetic.seed', 1, 'seed of the noise generator', bounds=Bounds(0))

    def relation_problem(self) -> tuple[str, str] | None:
        """What the values break together: ``(key, problem)``, or ``None``."""
        if self.light_dn <= self.dark_dn:
            return 'synthetic.light_dn', 'must be brighter than dark_dn'
        return None


@dataclass(frozen=True)
class TrackerSettings:
    """How the tracker detects, verifies and calibrates (``tracker.*``)."""

    detect_max_side_px: int = setting(
        'tracker.detect_max_side_px',
        640,
        'full detection runs on a copy shrunk to at most this longer side',
        'px',
        Bounds(160),
    )
    window_fraction: float = setting(
        'tracker.window_fraction',
        0.2,
        "corner refinement window half-size, as a fraction of a square's size in pixels",
        # A window reaching the neighbouring corner pulls the estimate toward it.
        bounds=Bounds(0.0, 0.5, low_open=True, high_open=True),
    )
    max_window_px: int = setting(
        'tracker.max_window_px',
        12,
        "the refinement window's largest half-size: a larger one averages more of the image "
        'into each corner, at a cost that grows with its area',
        'px',
        Bounds(3, 40),
    )
    max_homography_residual_px: float = setting(
        'tracker.max_homography_residual_px',
        1.0,
        'a frame is rejected when a homography through its corners misses one by more',
        'px',
        _POSITIVE,
    )
    max_rms_px: float = setting(
        'tracker.max_rms_px',
        0.5,
        'a pose is rejected when the RMS reprojection error of its fit exceeds this',
        'px',
        _POSITIVE,
    )
    min_contrast_dn: float = setting(
        'tracker.min_contrast_dn',
        20.0,
        'a frame is too dark when its 1st to 99th percentile spread is below this',
        'DN',
        _NON_NEGATIVE,
    )
    max_saturated_fraction: float = setting(
        'tracker.max_saturated_fraction',
        0.2,
        'a frame is saturated when more than this fraction of its pixels is at 255',
        bounds=_POSITIVE,
    )
    calibration_frames: int = setting(
        'tracker.calibration_frames',
        30,
        'good frames that estimate the camera distance and tilt before the refined extrinsics '
        'are used; 0 trusts the configured rig, else at least 3',
        bounds=Bounds(0),
    )
    calibration_min_step_m: float = setting(
        'tracker.calibration_min_step_m',
        0.001,
        'a good frame joins the calibration only if the tip moved this far since the last one',
        'm',
        _NON_NEGATIVE,
    )
    min_corners: int = setting(
        'tracker.min_corners',
        12,
        'a partial view gives a pose from at least this many corners',
        bounds=Bounds(6),
    )
    min_corner_spread: float = setting(
        'tracker.min_corner_spread',
        0.5,
        "a partial view's corners spread at least this far (rms) across their weakest direction",
        'squares',
        _POSITIVE,
    )
    max_depth_correction: float = setting(
        'tracker.max_depth_correction',
        0.03,
        'the rig calibration may put the board at most this fraction off its configured '
        'distance; farther, the board is not the one configured and every frame is refused',
        bounds=_POSITIVE,
    )
    tilt_prior_std_rad: float = setting(
        'tracker.tilt_prior_std_rad',
        5.0e-6,
        "how well the mount's out-of-plane tilt (camera.mount.rpy_rad) is known: the rig "
        'calibration fits the tilt with this Gaussian prior',
        'rad',
        _POSITIVE,
    )

    def relation_problem(self) -> tuple[str, str] | None:
        """What the values break together: ``(key, problem)``, or ``None``."""
        if 0 < self.calibration_frames < 3:
            return 'tracker.calibration_frames', 'must be 0 or at least 3'
        return None


#: The sections of ``config/camera.yaml``, in its order.
CAMERA_SECTIONS = (SensorSettings, BoardSettings, SyntheticSettings, TrackerSettings)

#: The parameters of ``config/camera.yaml``.
CAMERA_SETTINGS = tuple(spec for section in CAMERA_SECTIONS for spec in settings_specs(section))


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


def camera_config_from_parameters(params: Mapping[str, Any], source: str | Path) -> CameraConfig:
    """Builds and validates the camera configuration from flat (dotted) ROS parameters.

    Missing keys take the fields' defaults.

    Args:
        params: Flat parameters, e.g. from
            :func:`~lumpbeam_ros.base.paramfile.read_parameter_file`.
        source: Where they came from, for error messages.

    Returns:
        The configuration.

    Raises:
        ConfigError: An unknown key, a wrong type or an out-of-range value.
    """
    check_known_keys(params, frozenset(spec.name for spec in CAMERA_SETTINGS), source)
    sensor = settings_from_parameters(SensorSettings, params, source)
    board = settings_from_parameters(BoardSettings, params, source)
    camera_info = CameraInfo.pinhole(
        sensor.width_px,
        sensor.height_px,
        sensor.focal_length_px,
        sensor.principal_point_offset_px,
        sensor.distortion,
    )
    rig = RigGeometry(
        board=Checkerboard(
            board.squares_x, board.squares_y, board.square_size_m, board.margin_squares
        ),
        tip_camera=Transform.from_xyz_rpy(sensor.mount_xyz_m, sensor.mount_rpy_rad),
        base_board=Transform.from_xyz_rpy(board.xyz_m, board.rpy_rad),
    )
    return CameraConfig(
        camera_info,
        rig,
        settings_from_parameters(SyntheticSettings, params, source),
        settings_from_parameters(TrackerSettings, params, source),
    )


def load_camera_config(path: str | Path | None = None) -> CameraConfig:
    """Reads a camera parameter file (default: the package's ``config/camera.yaml``).

    Args:
        path: The YAML file, or ``None`` for the default.

    Returns:
        The configuration.

    Raises:
        ConfigError: The file is missing or malformed, or a value is invalid.
    """
    source, params = parameter_file(path, 'camera.yaml')
    return camera_config_from_parameters(params, source)


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
