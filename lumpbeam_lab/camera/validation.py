"""The camera's validation matrix: short drop tests filmed by the independent ray caster.

Each case renders a stretch of the model's drop test with
:class:`~lumpbeam_lab.camera.raycast_camera.RaycastCamera` (its own lens, geometry and
board code), gives the tracker the same set-up through a :class:`CameraConfig` and a
:class:`CameraInfo` (the mount tilt and the board's in-plane rotation are known from the
configuration; the rig calibration still runs), and scores every published pose with
:func:`~lumpbeam_lab.camera.accuracy.score`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from scipy.interpolate import CubicSpline

from lumpbeam_lab.camera.accuracy import AccuracyReport, score
from lumpbeam_lab.camera.raycast_camera import Lens, Optics, RaycastCamera, Scene
from lumpbeam_ros.core.model.trajectory import TipTrajectory
from lumpbeam_ros.core.vision.camera_model import CameraInfo
from lumpbeam_ros.core.vision.config import CameraConfig, RigGeometry, load_camera_config
from lumpbeam_ros.core.vision.geometry import Transform

#: Targets every case must meet (tip z, pitch: RMS with the bias in it).
Z_RMS_LIMIT_UM = 10.0
PITCH_RMS_LIMIT_MRAD = 0.05


@dataclass(frozen=True)
class ValidationCase:
    """One row of the matrix.

    Attributes:
        size_px: Image width and height, px.
        focal_px: fx = fy, px.
        centre_offset_px: Principal point minus the image centre, px.
        model: Distortion model.
        distortion: Its coefficients.
        defocus_px: Gaussian defocus, px.
        gradient: Illumination change across the image, peak to peak.
        flicker: Frame-to-frame illumination change, +-.
        noise_dn: Sensor noise, DN.
        mount_tilt_deg: Camera tilt on its mount about the tip's x and z axes, degrees.
        board_rotation_deg: Board rotation in its own plane, degrees.
        start_s: First frame's time in the drop test, s (the release is at 2 s).
        end_s: Last frame's time, s.
        frame_step: Film every ``frame_step``-th 180 Hz sample.
        exposure_s: Exposure, s.
        sub_exposures: Poses integrated over the exposure.
        seed: Noise seed.
        calibration_frames: Frames of the rig calibration; ``None`` keeps the
            configuration's (a short test may calibrate on fewer).
    """

    size_px: int = 1024
    focal_px: float = 1200.0
    centre_offset_px: tuple[float, float] = (0.0, 0.0)
    model: str = 'plumb_bob'
    distortion: tuple[float, ...] = (0.0, 0.0, 0.0, 0.0, 0.0)
    defocus_px: float = 0.0
    gradient: float = 0.0
    flicker: float = 0.0
    noise_dn: float = 0.0
    mount_tilt_deg: tuple[float, float] = (0.0, 0.0)
    board_rotation_deg: float = 0.0
    start_s: float = 1.95
    end_s: float = 2.75
    frame_step: int = 1
    exposure_s: float = 0.001
    sub_exposures: int = 4
    seed: int = 1
    calibration_frames: int | None = None

    def label(self) -> str:
        """The conditions, compactly."""
        d = ','.join(f'{v:g}' for v in self.distortion)
        return (
            f'{self.size_px}px f{self.focal_px:g} {self.model}({d}) '
            f'pp{self.centre_offset_px[0]:+g},{self.centre_offset_px[1]:+g} '
            f'blur{self.defocus_px:g} grad{100 * self.gradient:g}% '
            f'flk{100 * self.flicker:g}% noise{self.noise_dn:g} '
            f'tilt{self.mount_tilt_deg[0]:+g},{self.mount_tilt_deg[1]:+g} '
            f'rot{self.board_rotation_deg:+g}'
        )


def _rpy_mount(
    base: tuple[float, float, float], tilt_deg: tuple[float, float]
) -> tuple[float, float, float]:
    # Roll about the tip's x tilts the optical axis up/down; yaw about z turns it sideways.
    return (base[0] + math.radians(tilt_deg[0]), base[1], base[2] + math.radians(tilt_deg[1]))


def case_setup(case: ValidationCase) -> tuple[CameraInfo, CameraConfig, RaycastCamera]:
    """The tracker's intrinsics and configuration, and the renderer, for one case.

    Args:
        case: The conditions.

    Returns:
        ``(camera_info, config, renderer)``; the config is the package's ``camera.yaml``
        with the case's sensor, lens, mount tilt and board rotation.
    """
    base = load_camera_config()
    info = CameraInfo.pinhole(
        case.size_px, case.size_px, case.focal_px, case.centre_offset_px, case.distortion,
        case.model,
    )  # fmt: skip
    mount_xyz, mount_rpy = (0.0, 0.05, 0.0), (-math.pi / 2, 0.0, 0.0)
    board_x, board_y, board_z = (float(v) for v in base.rig.base_board.translation)
    board_xyz = (board_x, board_y, board_z)
    mount_rpy = _rpy_mount(mount_rpy, case.mount_tilt_deg)
    # Pitch about beam_base y is the board's normal: an in-plane rotation.
    board_rpy = (-math.pi / 2, math.radians(case.board_rotation_deg), 0.0)
    board = base.rig.board
    rig = RigGeometry(
        board=board,
        tip_camera=Transform.from_xyz_rpy(mount_xyz, mount_rpy),
        base_board=Transform.from_xyz_rpy(board_xyz, board_rpy),
    )
    tracker = base.tracker
    if case.calibration_frames is not None:
        tracker = replace(tracker, calibration_frames=case.calibration_frames)
    config = replace(base, camera_info=info, rig=rig, tracker=tracker)
    lens = Lens(
        info.width, info.height, info.k[0, 0], info.k[1, 1], info.k[0, 2], info.k[1, 2],
        case.model, tuple(float(v) for v in info.d),
    )  # fmt: skip
    scene = Scene(
        board.squares_x, board.squares_y, board.square_size_m, board.margin_squares,
        mount_xyz, mount_rpy, board_xyz, board_rpy,
    )  # fmt: skip
    optics = Optics(
        defocus_px=case.defocus_px, gradient=case.gradient, flicker=case.flicker,
        noise_dn=case.noise_dn, seed=case.seed,
    )  # fmt: skip
    return info, config, RaycastCamera(lens, scene, optics)


def run_case(case: ValidationCase, trajectory: TipTrajectory) -> AccuracyReport:
    """Films and tracks one case and scores every published pose.

    Args:
        case: The conditions.
        trajectory: The drop test (the truth).

    Returns:
        The report.
    """
    from lumpbeam_ros.core.vision.tracker import TipTracker

    info, config, camera = case_setup(case)
    spline = CubicSpline(
        trajectory.t, np.column_stack([trajectory.x, trajectory.z, trajectory.pitch]), axis=0
    )
    inside = (trajectory.t >= case.start_s) & (trajectory.t <= case.end_s)
    times = trajectory.t[inside][:: case.frame_step]
    steps = case.sub_exposures
    offsets = ((np.arange(steps) + 0.5) / steps - 0.5) * case.exposure_s
    tracker = TipTracker(info, config)
    results = []
    for index, stamp in enumerate(times):
        image = camera.render(spline(stamp + offsets), index)
        results.append(tracker.process(image, float(stamp)))
    return score(results, spline(times), info.width, info.height)


def matrix_cases(frame_step: int = 2) -> list[ValidationCase]:
    """The full validation matrix (the bench's ``camera-accuracy`` suite runs them all).

    Args:
        frame_step: Film every ``frame_step``-th 180 Hz sample (2: 90 fps, 73 frames of
            the release and the first swings per row).

    Returns:
        Six rows at 1024 x 1024 (f = 1200 px), then the same six at 2048 x 2048 (2400 px):
        an ideal pinhole; the modest plumb_bob lens of a machine-vision camera with uneven
        light and noise; strong barrel and pincushion plumb_bob lenses at the edge of the
        range with a tilted mount and a turned board; a rational_polynomial and an
        equidistant (fisheye) lens.
    """
    rows = []
    for size, focal in ((1024, 1200.0), (2048, 2400.0)):
        s = size / 1024
        rows += [
            ValidationCase(size, focal),
            ValidationCase(
                size, focal, (7.0 * s, -4.0 * s), 'plumb_bob', (-0.08, 0.02, 5e-4, -5e-4, 0.0),
                0.8, 0.3, 0.05, 2.5,
            ),
            ValidationCase(
                size, focal, (30.0, -30.0), 'plumb_bob', (-0.25, 0.1, 1e-3, 1e-3, 0.0), 1.5,
                0.3, 0.05, 3.0, (3.0, 2.0), 5.0,
            ),
            ValidationCase(
                size, focal, (-30.0, 20.0), 'plumb_bob', (0.25, -0.1, -1e-3, 1e-3, 0.0), 0.0,
                0.3, 0.05, 3.0, (-3.0, -3.0), -5.0,
            ),
            ValidationCase(
                size, focal, (15.0, 10.0), 'rational_polynomial',
                (0.3, -0.1, 5e-4, -5e-4, 0.02, 0.45, -0.05, 0.01), 1.0, 0.2, 0.05, 2.0,
                (2.0, -1.0), 3.0,
            ),
            ValidationCase(
                size, focal, (-10.0, 25.0), 'equidistant', (-0.05, 0.01, -0.003, 0.0005), 1.0,
                0.2, 0.05, 2.0, (-1.0, 2.0), -3.0,
            ),
        ]  # fmt: skip
    return [replace(row, frame_step=frame_step) for row in rows]


def format_row(case: ValidationCase, report: AccuracyReport) -> str:
    """One line of the printed matrix."""
    z = report.z_um
    ok = report.frames_lost == 0 and z.rms <= Z_RMS_LIMIT_UM
    ok = ok and report.pitch_mrad.rms <= PITCH_RMS_LIMIT_MRAD
    return (
        f'{case.label()} | frames {report.frames} lost {report.frames_lost} | z rms '
        f'{z.rms:.2f} bias {z.bias:+.2f} std {z.std:.2f} p99 {z.p99:.2f} max {z.max:.2f} um | '
        f'x rms {report.x_um.rms:.2f} um | pitch rms {report.pitch_mrad.rms:.4f} mrad | '
        f'{100 * report.within_1sigma:.0f} % within 1 sigma | {"PASS" if ok else "FAIL"}'
    )
