"""How well the tracker recovers the simulated drop test from synthetic frames.

The truth is the beam model's drop test (:func:`drop_test_trajectory`: the identified beam
of ``config/paper_beam.yaml``, 4.5 kg released at 2 s, 12 s at 180 Hz). Frames are rendered,
tracked and dropped one at a time, so a whole 12 s run at 2048 x 2048 (8.6 GB of pixels)
needs the memory of one frame.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from lumpbeam_ros.errors import LumpbeamError
from lumpbeam_ros.model.parameters import load_beam_config
from lumpbeam_ros.model.simulate import simulate_drop_test
from lumpbeam_ros.model.trajectory import TipTrajectory
from lumpbeam_ros.vision.calibration import adjusted_rig
from lumpbeam_ros.vision.config import CameraConfig, load_camera_config
from lumpbeam_ros.vision.synthetic import SyntheticCamera, SyntheticFrame
from lumpbeam_ros.vision.tracker import TipTracker, TrackResult

#: Rig errors the tracker starts from in :func:`measure_accuracy`: the camera mount tilted
#: 3 mrad about the tip's x and -2 mrad about z, the board 5 mm further than configured.
DEFAULT_RIG_ERROR = (0.003, -0.002, 0.005)


def drop_test_trajectory(
    rate_hz: float = 180.0, beam_config: str | Path | None = None
) -> TipTrajectory:
    """The model's drop test, the truth the synthetic camera films.

    Args:
        rate_hz: Sample rate, Hz.
        beam_config: Beam parameter file; ``None`` takes ``config/paper_beam.yaml`` (the
            identified beam, ``n_s`` = 10, physical tip-mass placement).

    Returns:
        The tip trajectory of the whole drop test.

    Raises:
        ConfigError: A bad beam file.
        LumpbeamError: A non-positive rate.
    """
    if not rate_hz > 0:
        raise LumpbeamError(f'drop-test trajectory: rate must be positive, got {rate_hz!r}')
    beam, drop = load_beam_config(beam_config)
    return simulate_drop_test(beam, drop, rate_hz)


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


def frame_times(trajectory: TipTrajectory, frame_step: int = 1) -> np.ndarray:
    """Exposure times: every ``frame_step``-th sample of the trajectory.

    Raises:
        LumpbeamError: ``frame_step`` below 1.
    """
    if frame_step < 1:
        raise LumpbeamError(f'frame step must be at least 1, got {frame_step!r}')
    return trajectory.t[::frame_step]


def iter_frames(
    config: CameraConfig, trajectory: TipTrajectory, times: np.ndarray | None = None
) -> Iterable[SyntheticFrame]:
    """Renders frames lazily, one per exposure time.

    Args:
        config: Camera set-up and rendering settings.
        trajectory: Tip trajectory (the spline the exposures are sampled from).
        times: Exposure midpoints, s; ``None`` for every trajectory sample.

    Returns:
        An iterator of frames.
    """
    camera = SyntheticCamera(config)
    return camera.render_trajectory(
        trajectory.t, trajectory.x, trajectory.z, trajectory.pitch, frame_times=times
    )


def render_frames(
    config: CameraConfig, trajectory: TipTrajectory, n_frames: int | None = None
) -> list[SyntheticFrame]:
    """Renders the first ``n_frames`` trajectory samples into memory (for timing runs).

    Args:
        config: Camera set-up and rendering settings.
        trajectory: Tip trajectory.
        n_frames: Frames to render; ``None`` for all samples (mind the memory).

    Returns:
        The frames.
    """
    times = trajectory.t if n_frames is None else trajectory.t[:n_frames]
    return list(iter_frames(config, trajectory, times))


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


def score(
    results: Sequence[TrackResult], truths: np.ndarray, width: int, height: int
) -> AccuracyReport:
    """Compares tracking results with the truth.

    Args:
        results: One result per frame, in order.
        truths: The true ``(x, z, pitch)`` of each frame (N x 3).
        width: Image width, px.
        height: Image height, px.

    Returns:
        The report.

    Raises:
        LumpbeamError: A count mismatch, or no calibrated frame has a pose.
    """
    truths = np.asarray(truths, dtype=float).reshape(-1, 3)
    if len(results) != len(truths):
        raise LumpbeamError(f'accuracy: {len(results)} results for {len(truths)} frames')
    scored = [i for i, r in enumerate(results) if r.ok and r.calibrated]
    if not scored:
        raise LumpbeamError('accuracy: no calibrated frame with a pose to score')
    error = np.array([results[i].pose for i in scored]) - truths[scored]
    mean = error.mean(axis=0)
    rms = np.sqrt(np.mean((error - mean) ** 2, axis=0))
    sigma_z = np.median([np.sqrt(results[i].covariance[1, 1]) for i in scored])
    return AccuracyReport(
        width=int(width),
        height=int(height),
        frames=len(results),
        frames_lost=sum(not r.ok for r in results),
        frames_calibrating=sum(r.ok and not r.calibrated for r in results),
        z_rms_um=float(rms[1] * 1e6),
        x_rms_um=float(rms[0] * 1e6),
        pitch_rms_mrad=float(rms[2] * 1e3),
        z_bias_um=float(mean[1] * 1e6),
        pitch_bias_mrad=float(mean[2] * 1e3),
        z_sigma_um=float(sigma_z * 1e6),
    )


def track_frames(
    tracker: TipTracker, frames: Iterable[SyntheticFrame]
) -> tuple[list[TrackResult], np.ndarray]:
    """Tracks frames as they come, keeping the results and truths but not the pixels.

    Returns:
        The results and the true poses (N x 3).
    """
    results, truths = [], []
    for frame in frames:
        results.append(tracker.process(frame.image, frame.stamp))
        truths.append(frame.truth)
    return results, np.asarray(truths, dtype=float).reshape(-1, 3)


def measure_accuracy(
    width: int = 2048,
    height: int = 2048,
    frame_step: int = 1,
    trajectory: TipTrajectory | None = None,
    config: CameraConfig | None = None,
    rig_error: Sequence[float] = DEFAULT_RIG_ERROR,
) -> AccuracyReport:
    """Films a trajectory, tracks it with a mis-configured rig, and scores the poses.

    The first ``tracker.calibration_frames`` poses estimate the rig and are not scored.

    Args:
        width: Image width, px (the focal length scales with it, same view).
        height: Image height, px.
        frame_step: Film every ``frame_step``-th sample (1: every frame, 180 fps). Larger
            steps make the tracker re-detect the board more often; the accuracy is the same.
        trajectory: The tip trajectory; ``None`` takes :func:`drop_test_trajectory`.
        config: The true set-up; ``None`` reads the package's ``config/camera.yaml``.
        rig_error: The tracker's out-of-plane rig error (see :func:`tracker_config`).

    Returns:
        The report.

    Raises:
        LumpbeamError: Too few frames to calibrate and score, or a bad configuration.
    """
    config = (load_camera_config() if config is None else config).with_resolution(width, height)
    trajectory = drop_test_trajectory() if trajectory is None else trajectory
    times = frame_times(trajectory, frame_step)
    tracker = TipTracker(config.camera_info, tracker_config(config, rig_error))
    results, truths = track_frames(tracker, iter_frames(config, trajectory, times))
    return score(results, truths, width, height)
