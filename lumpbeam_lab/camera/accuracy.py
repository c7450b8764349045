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

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import POSE_RATE_HZ
from lumpbeam_ros.core.model.parameters import load_beam_config
from lumpbeam_ros.core.model.simulate import simulate_drop_test
from lumpbeam_ros.core.model.trajectory import TipTrajectory
from lumpbeam_ros.core.vision.calibration import adjusted_rig
from lumpbeam_ros.core.vision.config import CameraConfig, load_camera_config
from lumpbeam_ros.core.vision.synthetic import SyntheticCamera, SyntheticFrame
from lumpbeam_ros.core.vision.tracker import TipTracker, TrackResult

#: Rig errors the tracker starts from in :func:`measure_accuracy`: the board 5 mm further
#: than configured. The mount's tilt is taken as measured (see ``tracker.tilt_prior_std_rad``:
#: images alone cannot pin it down to micrometres of tip position).
DEFAULT_RIG_ERROR = (0.0, 0.0, 0.005)


def drop_test_trajectory(
    rate_hz: float = POSE_RATE_HZ, beam_config: str | Path | None = None
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
class ErrorStats:
    """The honest summary of one coordinate's error over every published pose.

    Attributes:
        rms: RMS of (published - truth), the bias included.
        bias: Mean error.
        std: Standard deviation about the mean (the scatter, bias removed).
        p99: 99th percentile of the absolute error.
        max: Largest absolute error.
    """

    rms: float
    bias: float
    std: float
    p99: float
    max: float

    @staticmethod
    def of(errors: np.ndarray, scale: float = 1.0) -> ErrorStats:
        """Summarizes errors, multiplied by ``scale`` (e.g. 1e6 for micrometres).

        Args:
            errors: Published minus truth, one per pose (at least one).
            scale: Unit conversion factor.

        Returns:
            The statistics.
        """
        e = np.asarray(errors, dtype=float).ravel() * scale
        a = np.abs(e)
        return ErrorStats(
            rms=float(np.sqrt(np.mean(e * e))),
            bias=float(np.mean(e)),
            std=float(np.std(e)),
            p99=float(np.percentile(a, 99)),
            max=float(np.max(a)),
        )


@dataclass(frozen=True)
class AccuracyReport:
    """Tracking errors against the truth over every published pose.

    Every frame with a pose counts, the frames that calibrated the rig included, and the
    bias stays in the RMS: it is the error a user sees.

    Attributes:
        width: Image width, px.
        height: Image height, px.
        frames: Frames rendered.
        frames_lost: Frames without a pose.
        frames_calibrating: Frames published before the rig calibration completed (scored).
        x_um: Tip x error, micrometres.
        z_um: Tip z error, micrometres.
        pitch_mrad: Pitch error, mrad.
        z_within_1sigma: Fraction of poses whose z error is within the published 1-sigma
            (about 0.68 when the covariance is calibrated).
        within_1sigma: The same fraction for x, z and pitch together (each coordinate of
            each pose counted once).
        z_sigma_um: Median published z standard deviation, um.
    """

    width: int
    height: int
    frames: int
    frames_lost: int
    frames_calibrating: int
    x_um: ErrorStats
    z_um: ErrorStats
    pitch_mrad: ErrorStats
    z_within_1sigma: float
    within_1sigma: float
    z_sigma_um: float

    @property
    def z_rms_um(self) -> float:
        """RMS tip z error with the bias in it, um."""
        return self.z_um.rms

    @property
    def pitch_rms_mrad(self) -> float:
        """RMS pitch error with the bias in it, mrad."""
        return self.pitch_mrad.rms

    def summary(self) -> str:
        """One line for people."""
        z = self.z_um
        return (
            f'{self.width}x{self.height}: z rms {z.rms:.2f} um (bias {z.bias:+.2f}, std '
            f'{z.std:.2f}, p99 {z.p99:.2f}, max {z.max:.2f}), x rms {self.x_um.rms:.2f} um, '
            f'pitch rms {self.pitch_mrad.rms:.4f} mrad, '
            f'{100 * self.within_1sigma:.0f} % within 1 sigma, '
            f'{self.frames_lost} of {self.frames} frames lost'
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
    """Compares tracking results with the truth, over every published pose.

    Args:
        results: One result per frame, in order.
        truths: The true ``(x, z, pitch)`` of each frame (N x 3).
        width: Image width, px.
        height: Image height, px.

    Returns:
        The report.

    Raises:
        LumpbeamError: A count mismatch, or no frame has a pose.
    """
    truths = np.asarray(truths, dtype=float).reshape(-1, 3)
    if len(results) != len(truths):
        raise LumpbeamError(f'accuracy: {len(results)} results for {len(truths)} frames')
    scored = [i for i, r in enumerate(results) if r.ok]
    if not scored:
        raise LumpbeamError('accuracy: no frame with a pose to score')
    error = np.array([results[i].pose for i in scored]) - truths[scored]
    no_covariance = np.full(3, np.nan)  # counts as outside its band
    sigma = np.sqrt(
        np.array(
            [no_covariance if (c := results[i].covariance) is None else np.diag(c) for i in scored]
        )
    )
    inside = np.abs(error) <= sigma
    return AccuracyReport(
        width=int(width),
        height=int(height),
        frames=len(results),
        frames_lost=sum(not r.ok for r in results),
        frames_calibrating=sum(r.ok and not r.calibrated for r in results),
        x_um=ErrorStats.of(error[:, 0], 1e6),
        z_um=ErrorStats.of(error[:, 1], 1e6),
        pitch_mrad=ErrorStats.of(error[:, 2], 1e3),
        z_within_1sigma=float(np.mean(inside[:, 1])),
        within_1sigma=float(np.mean(inside)),
        z_sigma_um=float(np.median(sigma[:, 1]) * 1e6),
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
    """Films a trajectory, tracks it with a mis-configured rig, and scores every pose.

    The poses published while the rig is being calibrated are scored too.

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
