"""How well the tracker recovers a known tip trajectory from synthetic frames.

Until the beam model's ``simulate_drop_test`` is available here, the trajectory is a stand-in
with the drop test's character (:func:`stand_in_drop_trajectory`); swapping it is a one-line
change for the caller, who passes any :class:`TipTrajectory`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from lumpbeam_ros.errors import LumpbeamError
from lumpbeam_ros.model.trajectory import TipTrajectory
from lumpbeam_ros.vision.calibration import adjusted_rig
from lumpbeam_ros.vision.config import CameraConfig, load_camera_config
from lumpbeam_ros.vision.synthetic import SyntheticCamera, SyntheticFrame
from lumpbeam_ros.vision.tracker import TipTracker, TrackResult

#: Rig errors the tracker starts from in :func:`measure_accuracy`: the camera mount tilted
#: 3 mrad about the tip's x and -2 mrad about z, the board 5 mm further than configured.
DEFAULT_RIG_ERROR = (0.003, -0.002, 0.005)


def stand_in_drop_trajectory(
    duration_s: float = 1.0, rate_hz: float = 180.0, length_m: float = 2.3107
) -> TipTrajectory:
    """A damped tip oscillation after a load release, standing in for the beam model.

    ``z(t) = -0.01 - 0.04 exp(-0.06 * 2 pi * 3.1 t) cos(2 pi * 3.1 t)`` m from the release
    at ``t = 0``; pitch follows a cantilever's ``1.5 z / L``; x shortens by the tip's
    geometric foreshortening ``0.6 z^2 / L``.

    Args:
        duration_s: Length, s.
        rate_hz: Sample rate, Hz.
        length_m: Beam length L, m.

    Returns:
        The trajectory (no load after the release).

    Raises:
        LumpbeamError: A non-positive duration, rate or length.
    """
    if not (duration_s > 0 and rate_hz > 0 and length_m > 0):
        raise LumpbeamError('stand-in trajectory: duration, rate and length must be positive')
    t = np.arange(int(round(duration_s * rate_hz))) / rate_hz
    omega = 2.0 * np.pi * 3.1
    z = -0.01 - 0.04 * np.exp(-0.06 * omega * t) * np.cos(omega * t)
    return TipTrajectory(
        t=t,
        x=length_m - 0.6 * z * z / length_m,
        z=z,
        pitch=1.5 * z / length_m,
        load_kg=np.zeros_like(t),
    )


@dataclass(frozen=True)
class AccuracyReport:
    """Tracking errors against the truth on calibrated frames.

    Displacement errors have their mean removed: the absolute zero of the tip pose rests on
    the configured in-plane offsets of the camera and the board, which images cannot check.

    Attributes:
        width: Image width, px.
        height: Image height, px.
        frames: Frames rendered.
        frames_lost: Frames without a pose.
        frames_calibrating: Frames before the rig calibration completed (not scored).
        z_rms_um: RMS error of the tip's z displacement, micrometres.
        x_rms_um: RMS error of the tip's x displacement, micrometres.
        pitch_rms_mrad: RMS error of the pitch change, mrad.
        z_bias_um: Mean z error, micrometres.
        pitch_bias_mrad: Mean pitch error, mrad.
        z_sigma_um: Median z standard deviation the tracker claims (its covariance), um.
    """

    width: int
    height: int
    frames: int
    frames_lost: int
    frames_calibrating: int
    z_rms_um: float
    x_rms_um: float
    pitch_rms_mrad: float
    z_bias_um: float
    pitch_bias_mrad: float
    z_sigma_um: float

    def summary(self) -> str:
        """One line for people."""
        return (
            f'{self.width}x{self.height}: z {self.z_rms_um:.2f} um rms, pitch '
            f'{self.pitch_rms_mrad:.4f} mrad rms, x {self.x_rms_um:.2f} um rms, '
            f'{self.frames_lost} of {self.frames} frames lost, '
            f'{self.frames_calibrating} calibrating'
        )


def render_frames(
    config: CameraConfig, trajectory: TipTrajectory, n_frames: int | None = None
) -> list[SyntheticFrame]:
    """Renders one frame per trajectory sample (the first ``n_frames`` of them).

    Args:
        config: Camera set-up and rendering settings.
        trajectory: Tip trajectory.
        n_frames: Frames to render; ``None`` for all samples.

    Returns:
        The frames.
    """
    camera = SyntheticCamera(config)
    times = trajectory.t if n_frames is None else trajectory.t[:n_frames]
    return list(
        camera.render_trajectory(
            trajectory.t, trajectory.x, trajectory.z, trajectory.pitch, frame_times=times
        )
    )


def tracker_config(
    config: CameraConfig, rig_error: Sequence[float] = DEFAULT_RIG_ERROR
) -> CameraConfig:
    """The configuration a tracker believes: the true one with out-of-plane rig errors.

    Args:
        config: The true set-up (the one the frames were rendered with).
        rig_error: Camera tilt about the tip's x and z axes (rad) and board depth error (m).

    Returns:
        The perturbed configuration.
    """
    return replace(config, rig=adjusted_rig(config.rig, *rig_error))


def score(results: Sequence[TrackResult], frames: Sequence[SyntheticFrame]) -> AccuracyReport:
    """Compares tracking results with the truth.

    Args:
        results: One result per frame, in order.
        frames: The rendered frames with their true poses.

    Returns:
        The report.

    Raises:
        LumpbeamError: No calibrated frame has a pose.
    """
    scored = [(r, f) for r, f in zip(results, frames, strict=True) if r.ok and r.calibrated]
    if not scored:
        raise LumpbeamError('accuracy: no calibrated frame with a pose to score')
    error = np.array([r.pose - f.truth for r, f in scored])
    mean = error.mean(axis=0)
    rms = np.sqrt(np.mean((error - mean) ** 2, axis=0))
    sigma_z = np.median([np.sqrt(r.covariance[1, 1]) for r, _ in scored])
    camera = frames[0].image.shape
    return AccuracyReport(
        width=int(camera[1]),
        height=int(camera[0]),
        frames=len(frames),
        frames_lost=sum(not r.ok for r in results),
        frames_calibrating=sum(r.ok and not r.calibrated for r in results),
        z_rms_um=float(rms[1] * 1e6),
        x_rms_um=float(rms[0] * 1e6),
        pitch_rms_mrad=float(rms[2] * 1e3),
        z_bias_um=float(mean[1] * 1e6),
        pitch_bias_mrad=float(mean[2] * 1e3),
        z_sigma_um=float(sigma_z * 1e6),
    )


def measure_accuracy(
    width: int = 2048,
    height: int = 2048,
    n_frames: int = 120,
    trajectory: TipTrajectory | None = None,
    config: CameraConfig | None = None,
    rig_error: Sequence[float] = DEFAULT_RIG_ERROR,
) -> AccuracyReport:
    """Renders a trajectory, tracks it with a mis-configured rig, and scores the poses.

    Args:
        width: Image width, px (the focal length scales with it, same view).
        height: Image height, px.
        n_frames: Frames to render and track (180 Hz samples from the release on).
        trajectory: The tip trajectory; ``None`` takes :func:`stand_in_drop_trajectory`.
        config: The true set-up; ``None`` reads the package's ``config/camera.yaml``.
        rig_error: The tracker's out-of-plane rig error (see :func:`tracker_config`).

    Returns:
        The report.

    Raises:
        LumpbeamError: Too few frames to calibrate and score, or a bad configuration.
    """
    config = (load_camera_config() if config is None else config).with_resolution(width, height)
    if trajectory is None:
        trajectory = stand_in_drop_trajectory(duration_s=max(n_frames, 4) / 180.0 + 0.05)
    frames = render_frames(config, trajectory, n_frames)
    tracker = TipTracker(config.camera_info, tracker_config(config, rig_error))
    results = [tracker.process(frame.image, frame.stamp) for frame in frames]
    return score(results, frames)
