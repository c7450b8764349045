"""Tracker speed and accuracy against per-frame full detection, on the same frames.

Frames are rendered first; only the tracking is timed, on one OpenCV thread. The baseline is
what a calibration script does to every frame: ``findChessboardCorners`` on the full image,
``cornerSubPix`` with the usual 11 x 11 window, and a free 6-DoF ``solvePnP``.

Accuracy is scored on the model's whole drop test (every frame; every 20th in quick mode),
and the camera node is run end to end through ROS topics between processes
(:mod:`lumpbeam_lab.bench.camera_stream`).
"""

from __future__ import annotations

import math
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np
from scipy.interpolate import CubicSpline

from lumpbeam_lab.bench import camera_stream
from lumpbeam_lab.bench.bench_result import BenchResult
from lumpbeam_lab.camera.accuracy import (
    drop_test_trajectory,
    measure_accuracy,
    render_frames,
    tracker_config,
)
from lumpbeam_lab.camera.validation import ValidationCase, case_setup, matrix_cases
from lumpbeam_ros.core.vision.config import CameraConfig, RigGeometry, load_camera_config
from lumpbeam_ros.core.vision.pose import (
    PlaneModel,
    camera_board_transform,
    solve_board_pnp,
    tip_pose_from_board_pose,
)
from lumpbeam_ros.core.vision.synthetic import SyntheticFrame
from lumpbeam_ros.core.vision.tracker import TipTracker, TrackResult

_BASELINE = 'findChessboardCorners + cornerSubPix + solvePnP per frame'


#: The speed target of the 2048 x 2048 row with a distorting lens: frames per second and
#: times the baseline's.
TARGET_FPS = 180.0
TARGET_RATIO = 10.0


def _track_pass(
    tracker: TipTracker, frames: Sequence[SyntheticFrame], offset: float
) -> tuple[float, float, list[TrackResult]]:
    """One timed pass from a cold start: wall time, s, CPU time, s, and the results."""
    tracker.reset()
    cpu = time.process_time()
    start = time.perf_counter()
    results = [tracker.process(f.image, f.stamp + offset) for f in frames]
    return time.perf_counter() - start, time.process_time() - cpu, results


def _opencv_corners(image: np.ndarray, pattern_size: tuple[int, int]) -> np.ndarray | None:
    """A calibration script's corners: ``findChessboardCorners``, then ``cornerSubPix`` 11 px."""
    flags = cv2.CALIB_CB_ADAPTIVE_THRESH | cv2.CALIB_CB_NORMALIZE_IMAGE
    found, corners = cv2.findChessboardCorners(image, pattern_size, flags=flags)
    if not found:
        return None
    criteria = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_MAX_ITER, 30, 0.001)
    return np.asarray(cv2.cornerSubPix(image, corners, (11, 11), (-1, -1), criteria))


def _baseline_pass(
    frames: Sequence[SyntheticFrame], config: CameraConfig
) -> tuple[float, float, list[np.ndarray | None]]:
    """One timed pass of the baseline: wall time, s, CPU time, s, and the free poses."""
    board = config.rig.board
    objects = board.object_points()
    k = config.camera_info.k
    d = config.camera_info.d
    poses: list[np.ndarray | None] = []
    cpu = time.process_time()
    start = time.perf_counter()
    for frame in frames:
        corners = _opencv_corners(frame.image, board.pattern_size)
        if corners is None:
            poses.append(None)
            continue
        ok, rvec, tvec = cv2.solvePnP(objects, corners, k, d)
        poses.append(np.hstack([rvec.ravel(), tvec.ravel()]) if ok else None)
    return time.perf_counter() - start, time.process_time() - cpu, poses


def _baseline_z_rms_um(
    poses: Sequence[np.ndarray | None], frames: Sequence[SyntheticFrame], config: CameraConfig
) -> float:
    """z RMS error (bias in) of free PnP, each frame converted with the true rig."""
    from lumpbeam_ros.core.vision.geometry import Transform

    errors = []
    for pose, frame in zip(poses, frames, strict=True):
        if pose is None:
            continue
        camera_board = Transform(cv2.Rodrigues(pose[:3])[0], pose[3:])
        errors.append(tip_pose_from_board_pose(config.rig, camera_board)[1] - frame.truth[1])
    return float(np.sqrt(np.mean(np.square(errors))) * 1e6) if errors else float('nan')


#: A modest plumb_bob lens for the speed rows with distortion on.
LENS_DISTORTION = (-0.08, 0.02, 5e-4, -5e-4, 0.0)


def speed(
    width: int,
    height: int,
    n_frames: int,
    repeat: int,
    distortion: tuple[float, ...] = (0.0,) * 5,
) -> BenchResult:
    """In-process tracker fps against per-frame full detection, from just before the release.

    Args:
        width: Image width, px.
        height: Image height, px.
        n_frames: Frames held in memory and timed.
        repeat: Timed passes (the fastest counts).
        distortion: plumb_bob coefficients of the lens (rendered and given to both sides).

    Returns:
        The result; details hold both sides' CPU time per frame (of their fastest passes)
        and z RMS error on the same frames and, with a lens, whether the speed target
        (:data:`TARGET_FPS` and :data:`TARGET_RATIO`) is met.
    """
    config = load_camera_config().with_resolution(width, height)
    config = replace(config, camera_info=replace(config.camera_info, d=np.asarray(distortion)))
    trajectory = drop_test_trajectory().between(1.9, 12.0)
    frames = render_frames(config, trajectory, n_frames)
    threads = cv2.getNumThreads()
    cv2.setNumThreads(1)
    try:
        tracker = TipTracker(config.camera_info, tracker_config(config))
        # The first pass calibrates the rig; the timed passes then run the calibrated
        # tracker from a cold start (full detection on frame 1).
        duration = frames[-1].stamp - frames[0].stamp + 1.0
        _, _, first = _track_pass(tracker, frames, 0.0)
        passes = [_track_pass(tracker, frames, duration * (i + 1))[:2] for i in range(repeat)]
        baseline_passes = []
        for _ in range(max(1, repeat - 1)):
            elapsed, cpu, baseline_poses = _baseline_pass(frames, config)
            baseline_passes.append((elapsed, cpu))
    finally:
        cv2.setNumThreads(threads)
    fps = n_frames / min(t for t, _ in passes)
    baseline_fps = n_frames / min(t for t, _ in baseline_passes)
    cpu_ms = 1e3 * min(c for _, c in passes) / n_frames
    baseline_cpu_ms = 1e3 * min(c for _, c in baseline_passes) / n_frames
    z_error = [r.pose[1] - f.truth[1] for r, f in zip(first, frames, strict=True) if r.ok]
    details: dict[str, object] = {
        'frames': n_frames,
        'frames_lost': sum(not r.ok for r in first),
        'z_rms_um': float(np.sqrt(np.mean(np.square(z_error))) * 1e6),
        'baseline_frames_found': sum(p is not None for p in baseline_poses),
        'baseline_z_rms_um': _baseline_z_rms_um(baseline_poses, frames, config),
        'cpu_ms_per_frame': cpu_ms,
        'baseline_cpu_ms_per_frame': baseline_cpu_ms,
        'cpu_ratio': baseline_cpu_ms / cpu_ms,
    }
    lens = '_distorted' if any(distortion) else ''
    if lens:
        met = fps >= TARGET_FPS and fps / baseline_fps >= TARGET_RATIO
        details['target'] = (
            f'{"pass" if met else "FAIL"} (>= {TARGET_FPS:g} fps and >= {TARGET_RATIO:g}x)'
        )
    return BenchResult(
        f'tracker_fps_{width}x{height}{lens}', fps, 'frames/s', _BASELINE, baseline_fps,
        fps / baseline_fps, details,
    )  # fmt: skip


_OPENCV_PLANE = (
    "OpenCV's corners (findChessboardCorners, cornerSubPix 23 x 23) + the rig's plane fit"
)


def _opencv_plane_pass(
    frames: Sequence[SyntheticFrame], config: CameraConfig, rig: RigGeometry
) -> tuple[float, list[np.ndarray | None]]:
    """The best pipeline of OpenCV's own functions with the tracker's rig model, timed.

    Per frame: ``findChessboardCorners``, ``cornerSubPix`` with its usual 11 px half-window,
    undistortion, a PnP start and the 3-DoF plane fit of the same (calibrated) rig as the
    tracker's: the tracker's own model on OpenCV's corners.

    Returns:
        Wall time, s, and the poses ``(x, z, pitch)`` (``None``: board not found).
    """
    board = config.rig.board
    info = config.camera_info
    model = PlaneModel(rig, info)
    objects = board.object_points()
    expected = camera_board_transform(rig, np.array([0.0, 0.0, 0.0])).rotation
    poses: list[np.ndarray | None] = []
    start = time.perf_counter()
    for frame in frames:
        corners = _opencv_corners(frame.image, board.pattern_size)
        if corners is None:
            poses.append(None)
            continue
        ideal = info.undistort_pixels(corners.reshape(-1, 2).astype(np.float64))
        camera_board = solve_board_pnp(objects, ideal, info, expected)
        if camera_board is None:
            poses.append(None)
            continue
        fit = model.fit(ideal, tip_pose_from_board_pose(rig, camera_board))
        poses.append(fit.pose if fit.converged else None)
    return time.perf_counter() - start, poses


def _z_errors_um(
    poses: Sequence[np.ndarray | None], frames: Sequence[SyntheticFrame]
) -> np.ndarray:
    return np.array(
        [1e6 * (p[1] - f.truth[1]) for p, f in zip(poses, frames, strict=True) if p is not None]
    )


def versus_opencv(
    width: int,
    height: int,
    n_frames: int,
    repeat: int,
    distortion: tuple[float, ...] = (0.0,) * 5,
) -> BenchResult:
    """The tracker against the best OpenCV pipeline with the same rig model, on both axes.

    On the frames of the renderer the tests use (:mod:`lumpbeam_ros.core.vision.synthetic`),
    from just before the release; the tracker believes the board 5 mm off (it calibrates).

    Args:
        width: Image width, px.
        height: Image height, px.
        n_frames: Frames rendered from just before the release.
        repeat: Timed passes of each (the fastest counts).
        distortion: plumb_bob coefficients of the lens.

    Returns:
        See :func:`_versus`.
    """
    config = load_camera_config().with_resolution(width, height)
    config = replace(config, camera_info=replace(config.camera_info, d=np.asarray(distortion)))
    frames = render_frames(config, drop_test_trajectory().between(1.9, 12.0), n_frames)
    lens = '_distorted' if any(distortion) else ''
    name = f'tracker_vs_opencv_plane_{width}x{height}{lens}'
    return _versus(name, frames, config, tracker_config(config), repeat)


def versus_opencv_raycast(case: ValidationCase, repeat: int) -> BenchResult:
    """The same comparison on frames of the independent ray caster.

    :mod:`lumpbeam_lab.camera.raycast_camera` shares no camera, lens or board code with the
    tracker; ``case`` is a row of the camera's validation matrix (its lens, light and noise).

    Args:
        case: The conditions.
        repeat: Timed passes of each.

    Returns:
        See :func:`_versus`.
    """
    info, config, camera = case_setup(case)
    trajectory = drop_test_trajectory()
    spline = CubicSpline(
        trajectory.t, np.column_stack([trajectory.x, trajectory.z, trajectory.pitch]), axis=0
    )
    times = trajectory.t[(trajectory.t >= case.start_s) & (trajectory.t <= case.end_s)]
    times = times[:: case.frame_step]
    offsets = ((np.arange(case.sub_exposures) + 0.5) / case.sub_exposures - 0.5) * case.exposure_s
    frames = [
        SyntheticFrame(i, float(t), camera.render(spline(t + offsets), i), spline(t), offsets.size)
        for i, t in enumerate(times)
    ]
    lens = '_distorted' if any(case.distortion) else ''
    name = f'tracker_vs_opencv_plane_raycast_{case.size_px}x{case.size_px}{lens}'
    return _versus(name, frames, config, config, repeat)


def _versus(
    name: str,
    frames: Sequence[SyntheticFrame],
    config: CameraConfig,
    believed: CameraConfig,
    repeat: int,
) -> BenchResult:
    """Times and scores the tracker and OpenCV's pipeline on the same frames.

    Both run in the same run, one OpenCV thread each, the timed passes interleaved: the
    tracker's frame rate against the pipeline's (the ratio), and each one's tip z error over
    every frame, bias included (the tracker's first pass, which calibrates the rig; the
    pipeline fits the rig the tracker calibrated).

    Args:
        name: The row's name.
        frames: The frames, with the truth.
        config: The camera the frames were filmed with.
        believed: The configuration the tracker is given.
        repeat: Timed passes of each (the fastest counts).

    Returns:
        The result; details hold both sides' z RMS, bias and max, the accuracy lead (the
        pipeline's RMS over the tracker's) and the OpenCV version.
    """
    threads = cv2.getNumThreads()
    cv2.setNumThreads(1)
    try:
        tracker = TipTracker(config.camera_info, believed)
        duration = frames[-1].stamp - frames[0].stamp + 1.0
        _, _, first = _track_pass(tracker, frames, 0.0)
        rig = tracker.calibration.rig if tracker.calibration else believed.rig
        fastest, opencv_fastest = math.inf, math.inf
        for i in range(repeat):  # interleaved: a busy spell slows both alike
            fastest = min(fastest, _track_pass(tracker, frames, duration * (i + 1))[0])
            elapsed, poses = _opencv_plane_pass(frames, config, rig)
            opencv_fastest = min(opencv_fastest, elapsed)
    finally:
        cv2.setNumThreads(threads)
    ours = _z_errors_um([r.pose if r.ok else None for r in first], frames)
    theirs = _z_errors_um(poses, frames)
    fps, opencv_fps = len(frames) / fastest, len(frames) / opencv_fastest
    details: dict[str, object] = {'opencv': cv2.__version__, 'frames': len(frames)}
    for label, errors in (('', ours), ('opencv_', theirs)):
        details[f'{label}poses'] = int(errors.size)
        details[f'{label}z_rms_um'] = float(np.sqrt(np.mean(errors**2)))
        details[f'{label}z_bias_um'] = float(np.mean(errors))
        details[f'{label}z_max_um'] = float(np.max(np.abs(errors)))
    details['accuracy_lead'] = details['opencv_z_rms_um'] / details['z_rms_um']  # type: ignore[operator]
    return BenchResult(
        name, fps, 'frames/s', _OPENCV_PLANE, opencv_fps, fps / opencv_fps, details
    )  # fmt: skip


#: The end-to-end target of ``lumpbeam track``: times the plain script's frame rate.
TRACK_TARGET_RATIO = 2.0


def _wall_s(command: list[str]) -> float:
    """Wall time of a command run to its end, s (it must succeed)."""
    start = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start


def track_end_to_end(width: int, height: int, duration_s: float, repeat: int) -> BenchResult:
    """``lumpbeam track`` as a process against a plain script reading the same bag.

    The bag is a synthetic drop test filmed at ``width`` x ``height`` (release at 2 s). Both
    run as processes, start-up included, on an otherwise idle machine: ``lumpbeam track``
    (reading, tracking, the output bag, the truth comparison) and
    :mod:`lumpbeam_lab.bench.plain_track` (reading and tracking only).

    Args:
        width: Image width, px.
        height: Image height, px.
        duration_s: The drop test's length, s (180 frames a second).
        repeat: Runs of each, alternated (the fastest counts).

    Returns:
        Frames per second of wall time of each, and whether the target
        (:data:`TRACK_TARGET_RATIO` times the plain script) is met.
    """
    from lumpbeam_ros.core.model.parameters import load_beam_config
    from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, write_drop_test_bag
    from lumpbeam_ros.core.synthetic.images import ImageOptions

    with tempfile.TemporaryDirectory(prefix='lumpbeam-bench-') as folder:
        bag, out = Path(folder) / 'filmed', Path(folder) / 'tracked'
        beam, drop = load_beam_config()
        options, images = SynthOptions(duration_s=duration_s), ImageOptions(width, height)
        trajectory, _ = write_drop_test_bag(bag, beam, drop, options, images=images)
        frames = len(trajectory.t)
        lumpbeam = [sys.executable, '-m', 'lumpbeam_ros.apps.cli.main']
        track = [*lumpbeam, 'track', str(bag), str(out), '--quiet', '--force']
        plain = [sys.executable, '-m', 'lumpbeam_lab.bench.plain_track', str(bag)]
        plain += [str(width), str(height)]
        ours, theirs = math.inf, math.inf
        for _ in range(repeat):
            ours = min(ours, _wall_s(track))
            theirs = min(theirs, _wall_s(plain))
    fps, plain_fps = frames / ours, frames / theirs
    met = fps >= TRACK_TARGET_RATIO * plain_fps
    details: dict[str, object] = {
        'frames': frames,
        'track_wall_s': ours,
        'plain_wall_s': theirs,
        'target': f'{"pass" if met else "FAIL"} (>= {TRACK_TARGET_RATIO:g}x)',
    }
    baseline = 'a plain script: iter_images + TrackingSession'
    return BenchResult(
        f'track_e2e_{width}x{height}', fps, 'frames/s', baseline, plain_fps, fps / plain_fps,
        details,
    )  # fmt: skip


def accuracy(width: int, height: int, frame_step: int) -> BenchResult:
    """z RMS error (every pose, bias in) on the drop test, against the 10 um target."""
    report = measure_accuracy(width, height, frame_step=frame_step)
    details = {
        'frames': report.frames,
        'frame_step': frame_step,
        'frames_lost': report.frames_lost,
        'frames_calibrating (scored)': report.frames_calibrating,
        'z_bias_um': report.z_um.bias,
        'z_std_um': report.z_um.std,
        'z_p99_um': report.z_um.p99,
        'z_max_um': report.z_um.max,
        'x_rms_um': report.x_um.rms,
        'pitch_rms_mrad': report.pitch_mrad.rms,
        'z_sigma_claimed_um': report.z_sigma_um,
        'within_1sigma': report.within_1sigma,
    }
    return BenchResult(
        f'tracker_z_rms_{width}x{height}', report.z_rms_um, 'um', 'target 10 um', 10.0,
        10.0 / report.z_rms_um, details,
    )  # fmt: skip


def end_to_end(
    width: int, height: int, rate_hz: float, duration_s: float, default_transport: bool = True
) -> list[BenchResult]:
    """The camera node in its own process against an echo node.

    Args:
        width: Image width, px.
        height: Image height, px.
        rate_hz: Offered frame rate, Hz.
        duration_s: Publishing time, s.
        default_transport: Also run with Fast DDS's default transports (after the 32 MB
            shared-memory profile).

    Returns:
        One result per transport.
    """
    results = []
    frames = camera_stream.drop_test_frames(width, height, rate_hz, duration_s)
    transports = ((True, 'shm32mb'), (False, 'default'))
    for large, label in transports if default_transport else transports[:1]:
        node = camera_stream.measure(camera_stream.camera_node_command(), frames, rate_hz, large)
        echo = camera_stream.measure(camera_stream.echo_command(), frames, rate_hz, large)
        value = node.received / node.duration_s
        baseline = echo.received / echo.duration_s
        details = {
            'offered_fps': rate_hz,
            'published': node.published,
            'poses_received': node.received,
            'latency_p50_ms': node.percentile_ms(50),
            'latency_p99_ms': node.percentile_ms(99),
            'echo_published': echo.published,
            'echo_received': echo.received,
            'echo_latency_p50_ms': echo.percentile_ms(50),
            'echo_latency_p99_ms': echo.percentile_ms(99),
        }
        results.append(
            BenchResult(
                f'camera_node_e2e_{width}x{height}_{label}',
                value,
                'poses/s',
                'echo node: decode + publish, no tracking',
                baseline,
                value / baseline if baseline > 0 else float('nan'),
                details,
            )  # fmt: skip
        )
    return results


def run(quick: bool) -> list[BenchResult]:
    """Runs the suite.

    Args:
        quick: A smoke test: 640 x 480, 45 timed frames, every 20th frame scored, 1 s of
            320 x 240 end to end (shared memory only), ``lumpbeam track`` of 2.2 s of
            320 x 240 once.

    Returns:
        Speed at 2048 x 2048 with a distorting lens, and without at 2048, 1024 and 640;
        against OpenCV's best pipeline at 1024 and 2048, with and without the lens, on
        the renderer the tests use and on the independent ray caster; then ``lumpbeam
        track`` as a process against a plain script (:func:`track_end_to_end`);
        accuracy at the three sizes on the whole
        drop test, then the end-to-end figures at 1024 x 1024 offered at 180 fps.
    """
    if quick:
        return [
            speed(640, 480, 45, repeat=2, distortion=LENS_DISTORTION),
            versus_opencv(640, 480, 45, repeat=2),
            accuracy(640, 480, frame_step=20),
            *end_to_end(320, 240, 180.0, 1.0, default_transport=False),
            track_end_to_end(320, 240, 2.2, repeat=1),
        ]
    results = [speed(2048, 2048, 150, repeat=5, distortion=LENS_DISTORTION)]
    results += [speed(w, h, 150, repeat=3) for w, h in ((2048, 2048), (1024, 1024), (640, 480))]
    results += [
        versus_opencv(size, size, 200, repeat=3, distortion=lens)
        for size in (1024, 2048)
        for lens in ((0.0,) * 5, LENS_DISTORTION)
    ]
    # The ideal pinhole and the machine-vision lens with uneven light and noise, per size.
    cases = matrix_cases(frame_step=1)
    results += [versus_opencv_raycast(cases[i], repeat=3) for i in (0, 1, 6, 7)]
    results += [accuracy(w, h, 1) for w, h in ((2048, 2048), (1024, 1024), (640, 480))]
    results += end_to_end(1024, 1024, 180.0, 4.0)
    results.append(track_end_to_end(1024, 1024, 3.0, repeat=3))
    return results
