"""Input shaping's speed: a long trajectory shaped, and an arm's move tuned by its model.

``shape_zvd_*``: a 10,000-point trajectory shaped, against ``scipy.signal.fftconvolve``.

Ours sums one linear interpolation of each joint per impulse
(:func:`~lumpbeam_ros.core.shaping.apply.shape_trajectory`). The baseline convolves the same 1 kHz
samples, held at their last value for the shaper's duration, with the impulse train placed
on the nearest 1 kHz sample (so it differs from ours by the impulses' rounding, reported as
``max_difference_rad``). Both are timed per joint, best of several runs.

``shape_tuned_3link_1s``: one 1 s move of ``config/arm_3link.yaml`` (every joint, a minimum
jerk through 0.8 to 1.4 rad) shaped by
:class:`~lumpbeam_ros.core.shaping.workspace.WorkspaceShaper` for the model's first two modes
at its end, tuned (``--tune``) against untuned in the same run, in CPU seconds: the target
is a tuned move in under 1 s of CPU.

``shaper_model_latency``: what the shaper node with ``source: model`` spends on one
``/joint_trajectory`` (the same move as a command of 100 points), untuned: the model's
modes at its end, the shaper, the shaped command; its p99 over many runs against the fixed
shaper's (``source: parameters``, the impulses given) in the same run. The target is a p99
under 20 ms.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from scipy.signal import fftconvolve

from lumpbeam_lab.bench.bench_result import BenchResult, best_time
from lumpbeam_lab.shaping_loop import minimum_jerk
from lumpbeam_ros.core.model.arm.config import load_arm_config
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.shaping.apply import shape_trajectory
from lumpbeam_ros.core.shaping.impulses import Impulses, Mode
from lumpbeam_ros.core.shaping.shapers import design_shaper
from lumpbeam_ros.core.shaping.workspace import WorkspaceShaper

BASELINE = 'scipy.signal.fftconvolve'
STEP_S = 1e-3
JOINTS = 3
ARM_FILE = Path(__file__).resolve().parents[2] / 'config' / 'arm_3link.yaml'
#: The bench's move of the three-link arm: start, end (rad), duration (s).
TUNED_MOVE = ((0.0, 0.5, -0.5), (0.8, -0.6, 0.9), 1.0)
#: A tuned 1 s move must take less CPU than this, s.
TUNED_CPU_TARGET_S = 1.0
#: The shaper node's processing of a command by the model must stay under this at p99, ms.
LATENCY_TARGET_MS = 20.0


def _trajectory(points: int) -> JointTrajectory:
    """A 1 kHz trajectory of ``points`` samples: three joints in smooth back-and-forth moves."""
    t = np.arange(points) * STEP_S
    phase = 2 * np.pi * t / t[-1]
    angles = np.column_stack([np.sin(k * phase) * (1 - np.cos(phase)) / k for k in (1, 2, 3)])
    return JointTrajectory(t, angles)


def _fft_shaped(trajectory: JointTrajectory, impulses: Impulses) -> np.ndarray:
    """The baseline: each joint convolved with the impulse train on the 1 kHz grid."""
    index = np.rint(impulses.time_s / STEP_S).astype(int)
    train = np.zeros(index[-1] + 1)
    np.add.at(train, index, impulses.amplitude)
    held = np.concatenate(
        [trajectory.angles_rad, np.repeat(trajectory.angles_rad[-1:], index[-1], axis=0)]
    )
    count = held.shape[0]
    return np.column_stack([fftconvolve(column, train)[:count] for column in held.T])


def shaping_speed(name: str, modes: list[Mode], points: int, repeat: int) -> BenchResult:
    """Shapes a ``points``-sample trajectory for ``modes`` (ZVD); the time per joint."""
    trajectory = _trajectory(points)
    impulses = design_shaper('zvd', modes)
    ours, shaped = best_time(lambda: shape_trajectory(trajectory, impulses), repeat)
    theirs, baseline = best_time(lambda: _fft_shaped(trajectory, impulses), repeat)
    rows = min(shaped.time_s.size, baseline.shape[0])
    value, baseline_value = ours / JOINTS * 1e3, theirs / JOINTS * 1e3
    return BenchResult(
        name=name,
        value=value,
        unit='ms per joint',
        baseline=BASELINE,
        baseline_value=baseline_value,
        ratio=baseline_value / value,
        details={
            'points': points,
            'joints': JOINTS,
            'impulses': int(impulses.time_s.size),
            'shaped_samples': int(shaped.time_s.size),
            'max_difference_rad': float(np.abs(shaped.angles_rad[:rows] - baseline[:rows]).max()),
        },
    )


def tuned_move(repeat: int) -> BenchResult:
    """The three-link arm's move shaped by its model: tuned against untuned, CPU seconds."""
    arm = load_arm_config(ARM_FILE)
    start, end, duration = TUNED_MOVE
    move = minimum_jerk(np.array(start), np.array(end), duration)
    untuned_shaper = WorkspaceShaper(arm, 'zvd', 2)
    untuned_s, untuned = best_time(
        lambda: untuned_shaper.shape_move(move), repeat, time.process_time
    )
    tuner = WorkspaceShaper(arm, 'zvd', 2, tune=True)
    tuned_s, tuned = best_time(lambda: tuner.shape_move(move), repeat, time.process_time)
    return BenchResult(
        name='shape_tuned_3link_1s',
        value=tuned_s,
        unit='CPU s',
        baseline='the same move shaped untuned (modes, ZVD, both predictions)',
        baseline_value=untuned_s,
        ratio=untuned_s / tuned_s,
        details={
            'unshaped_residual_m': tuned.predicted_residual_unshaped_m,
            'untuned_residual_m': untuned.predicted_residual_shaped_m,
            'tuned_residual_m': tuned.predicted_residual_shaped_m,
            'tuned_reduction': tuned.reduction,
            'target': f'{"pass" if tuned_s < TUNED_CPU_TARGET_S else "FAIL"} '
            f'(a tuned 1 s move in < {TUNED_CPU_TARGET_S:g} s of CPU)',
        },
    )


def _percentile_ms(function: Callable[[], object], runs: int, q: float) -> float:
    """The ``q`` percentile of ``runs`` wall times of ``function``, ms."""
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return float(np.percentile(times, q)) * 1e3


def model_latency(runs: int) -> BenchResult:
    """The shaper node's work on one command with ``source: model``, untuned, p99 in ms."""
    arm = load_arm_config(ARM_FILE)
    start, end, duration = TUNED_MOVE
    fine = minimum_jerk(np.array(start), np.array(end), duration)
    command = JointTrajectory(fine.time_s[::10], fine.angles_rad[::10])
    shaper = WorkspaceShaper(arm, 'zv', 2, predict=False)
    _, moves = shaper.shape(command)
    impulses = moves[0].impulses
    ours = _percentile_ms(lambda: shaper.shape(command), runs, 99)
    fixed = _percentile_ms(lambda: shape_trajectory(command, impulses), runs, 99)
    return BenchResult(
        name='shaper_model_latency',
        value=ours,
        unit='ms p99',
        baseline='the fixed shaper (source parameters) on the same command',
        baseline_value=fixed,
        ratio=fixed / ours,
        details={
            'points': int(command.time_s.size),
            'runs': runs,
            'p50_ms': _percentile_ms(lambda: shaper.shape(command), runs, 50),
            'target': f'{"pass" if ours < LATENCY_TARGET_MS else "FAIL"} '
            f'(p99 < {LATENCY_TARGET_MS:g} ms)',
        },
    )


def run(quick: bool = False) -> list[BenchResult]:
    """Runs the shaping suite.

    Args:
        quick: 1,000 points, one run each.

    Returns:
        A ZVD shaper for one mode (3 impulses), then for two modes (9 impulses), then the
        three-link arm's move tuned, then the shaper node's work by the model.
    """
    points, repeat = (1_000, 1) if quick else (10_000, 20)
    one = [Mode(2.0, 0.02)]
    two = [Mode(2.0, 0.02), Mode(7.3, 0.03)]
    return [
        shaping_speed(f'shape_zvd_1mode_{points}pts', one, points, repeat),
        shaping_speed(f'shape_zvd_2modes_{points}pts', two, points, repeat),
        tuned_move(1 if quick else 3),
        model_latency(10 if quick else 200),
    ]
