"""The arm's simulation: a three-link arm moved and left to ring down, against MuJoCo.

The case is ``config/arm_3link.yaml`` (10 segments per link, 30 in all): a 2 s rest-to-rest
cycloidal move of the three joints (0.6, -0.9, 0.7 rad) given as a 1 kHz trajectory, then
8 s of ring-down, the tip sampled at 200 Hz. Three runs of the same case, side by side:

- ours: :func:`~lumpbeam_ros.core.model.arm.simulate.simulate_arm` (the modal method), best of a
  few;
- the tight reference: the same equations by LSODA at ``rtol`` 1e-11 (it moves by a few
  nanometres from ``rtol`` 1e-9), against which both are scored: the tip's distance, RMS
  and largest over every sample;
- MuJoCo (:class:`lumpbeam_lab.mujoco_arm.MujocoArm`, its own multibody model of the same
  arm, the whole run in its C loop ``mujoco.rollout``) with RK4 at its cheapest step whose
  largest tip error is no worse than ours: the search starts just inside RK4's stability
  limit for the arm's fastest eigenvalue (the clamp dampers' overdamped modes, hundreds of
  thousands per second) and halves the step until it is as accurate as ours.

Then the cost as the chain grows: 10, 30 and 100 segments per link against real time.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from lumpbeam_lab.bench.bench_result import BenchResult, best_time
from lumpbeam_ros.core.model.arm.config import ArmConfig, arm_from_mapping
from lumpbeam_ros.core.model.arm.drive import SampledMotion
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.simulate import ArmMotion, simulate_arm
from lumpbeam_ros.core.model.arm.statics import arm_equilibrium, arm_linear_model

CONFIG = Path(__file__).resolve().parents[2] / 'config' / 'arm_3link.yaml'
MOVE_S = 2.0
AMPLITUDE_RAD = (0.6, -0.9, 0.7)
TRAJECTORY_STEP_S = 1e-3
RATE_HZ = 200.0
REFERENCE_RTOL = 1e-11
#: RK4 is stable for ``|lambda| h`` up to 2.78 on the real axis; start a little inside.
RK4_STABLE = 2.5
#: Steps tried below the stability limit (each half the last) before giving up.
MUJOCO_TRIES = 2
#: The targets: times faster than real time, and than MuJoCo at equal accuracy.
REAL_TIME_TARGET = 200.0
MUJOCO_TARGET = 20.0


def arm_config(segments: int, source: Path = CONFIG) -> ArmConfig:
    """The three-link arm with ``segments`` per link (a list of EI resampled along the link)."""
    document: Any = yaml.safe_load(source.read_text())
    for link in document['arm']['links']:
        ei = link['ei_nm2'] if 'ei_nm2' in link else None
        if isinstance(ei, list) and len(ei) != segments:
            centres = (np.arange(len(ei)) + 0.5) / len(ei)
            link['ei_nm2'] = np.interp(
                (np.arange(segments) + 0.5) / segments, centres, ei
            ).tolist()
        link['n_segments'] = segments
    return arm_from_mapping(document, source)


def move(n_joints: int, move_s: float) -> SampledMotion:
    """The rest-to-rest cycloidal move as a 1 kHz trajectory."""
    t = np.arange(round(move_s / TRAJECTORY_STEP_S) + 1) * TRAJECTORY_STEP_S
    s = t / move_s
    profile = s - np.sin(2 * np.pi * s) / (2 * np.pi)
    return SampledMotion.from_arrays(t, np.outer(profile, AMPLITUDE_RAD[:n_joints]))


def _gap(x: np.ndarray, z: np.ndarray, reference: ArmMotion) -> tuple[float, float]:
    """RMS and largest tip distance from the reference, m."""
    gap = np.hypot(x - reference.tip_x, z - reference.tip_z)
    return float(np.sqrt(np.mean(gap**2))), float(gap.max())


def _timed(function: Callable[[], ArmMotion], repeat: int) -> tuple[float, float, ArmMotion]:
    """The best wall and the best CPU time of ``repeat`` calls, and the last result."""
    walls, cpus = [], []
    for _ in range(max(1, repeat)):
        start, start_cpu = time.perf_counter(), time.process_time()
        result = function()
        walls.append(time.perf_counter() - start)
        cpus.append(time.process_time() - start_cpu)
    return min(walls), min(cpus), result


def _mujoco(
    config: ArmConfig, model: ArmModel, motion: SampledMotion, duration: float, step: float
) -> tuple[float, float, np.ndarray, np.ndarray]:
    """MuJoCo's RK4 at ``step`` from the same rest, following the same spline of the samples."""
    from lumpbeam_lab.mujoco_arm import MujocoArm

    spline = motion.spline()
    arm = MujocoArm(config, step)
    rest = arm_equilibrium(model, motion.angles(0.0))
    arm.set_absolute(rest, np.zeros_like(rest))

    def drives(times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        q, q_dot, _ = spline.sample(times)
        return q, q_dot

    run = arm.rollout(drives, duration, 1.0 / RATE_HZ)
    return float(run['wall_s']), float(run['cpu_s']), run['x'], run['z']


def _rk4_steps(model: ArmModel, q0: np.ndarray, tries: int) -> list[float]:
    """Steps that divide the sample interval, from inside RK4's stability limit, halving."""
    fastest = float(np.abs(np.linalg.eigvals(arm_linear_model(model, q0).state_matrix())).max())
    interval = 1.0 / RATE_HZ
    step = interval / np.ceil(interval * fastest / RK4_STABLE)
    return [float(step) / 2**k for k in range(tries)]


def against_mujoco(
    segments: int, move_s: float, duration: float, repeat: int, tries: int = MUJOCO_TRIES
) -> BenchResult:
    """Ours, the tight reference and MuJoCo on the same case, timed and scored."""
    config = arm_config(segments)
    model = ArmModel.from_config(config)
    motion = move(model.n_joints, move_s)
    t = np.arange(round(duration * RATE_HZ) + 1) / RATE_HZ
    ours, ours_cpu, result = _timed(lambda: simulate_arm(model, motion, t), repeat)
    start = time.perf_counter()
    reference = simulate_arm(
        model, motion, t, rtol=REFERENCE_RTOL, atol=REFERENCE_RTOL * 1e-2, method='lsoda'
    )
    reference_s = time.perf_counter() - start
    looser = simulate_arm(model, motion, t, rtol=1e-9, atol=1e-11, method='lsoda')
    # The method before this one: LSODA while the joints move, the modal ring-down after.
    lsoda_s, lsoda = best_time(lambda: simulate_arm(model, motion, t, method='lsoda'), 1)
    our_rms, our_max = _gap(result.tip_x, result.tip_z, reference)
    tried = []
    mujoco_s = mujoco_cpu = mujoco_rms = mujoco_max = float('nan')
    mujoco_step = float('nan')
    for step in _rk4_steps(model, motion.angles(0.0), tries):
        mujoco_s, mujoco_cpu, x, z = _mujoco(config, model, motion, duration, step)
        mujoco_rms, mujoco_max = _gap(x, z, reference)
        mujoco_step = step
        tried.append(f'{step:.3g} s: max {mujoco_max:.3g} m in {mujoco_s:.3g} s')
        if mujoco_max <= our_max:
            break
    real_time = duration / ours
    ratio = mujoco_s / ours
    # On a shared machine the CPU seconds are the one-core figure; the wall is what was seen.
    real_time_cpu = duration / ours_cpu
    ratio_cpu = mujoco_cpu / ours_cpu
    reached = mujoco_max <= our_max
    return BenchResult(
        name=f'arm_3link_ns{segments}_{duration:g}s',
        value=ours,
        unit='s',
        baseline=f'MuJoCo RK4 (mujoco.rollout), step {mujoco_step:.3g} s',
        baseline_value=mujoco_s,
        ratio=ratio,
        details={
            'simulated_s': duration,
            'real_time_factor': real_time,
            'cpu_s': ours_cpu,
            'real_time_factor_cpu': real_time_cpu,
            'mujoco_cpu_s': mujoco_cpu,
            'ratio_cpu': ratio_cpu,
            'tip_rms_m': our_rms,
            'tip_max_m': our_max,
            'mujoco_tip_rms_m': mujoco_rms,
            'mujoco_tip_max_m': mujoco_max,
            'mujoco_steps_tried': '; '.join(tried),
            'lsoda_s': lsoda_s,
            'lsoda_tip_max_m': _gap(lsoda.tip_x, lsoda.tip_z, reference)[1],
            'reference': f'LSODA rtol {REFERENCE_RTOL:g}, {reference_s:.3g} s; it moves by '
            f'{_gap(looser.tip_x, looser.tip_z, reference)[1]:.2g} m from rtol 1e-9',
            'target': (
                f'{"pass" if real_time >= REAL_TIME_TARGET else "FAIL"} wall, '
                f'{"pass" if real_time_cpu >= REAL_TIME_TARGET else "FAIL"} CPU '
                f'(>= {REAL_TIME_TARGET:g}x real time); '
                f'{"pass" if ratio >= MUJOCO_TARGET and reached else "FAIL"} wall, '
                f'{"pass" if ratio_cpu >= MUJOCO_TARGET and reached else "FAIL"} CPU '
                f'(>= {MUJOCO_TARGET:g}x MuJoCo at equal accuracy'
                f'{"" if reached else "; MuJoCo did not reach it: its time is a lower bound"})'
            ),
        },
    )


def scaling(segments: int, move_s: float, duration: float) -> BenchResult:
    """Wall time of the same move with ``segments`` per link, against real time."""
    model = ArmModel.from_config(arm_config(segments))
    motion = move(model.n_joints, move_s)
    t = np.arange(round(duration * RATE_HZ) + 1) / RATE_HZ
    wall, cpu, result = _timed(lambda: simulate_arm(model, motion, t), 1)
    return BenchResult(
        name=f'arm_3link_ns{segments}_cost',
        value=wall,
        unit='s',
        baseline='real time',
        baseline_value=duration,
        ratio=duration / wall,
        details={
            'segments': 3 * segments,
            'ms_per_simulated_s': wall / duration * 1e3,
            'cpu_s': cpu,
            'real_time_factor_cpu': duration / cpu,
            'method': result.method,
        },
    )


def run(quick: bool = False) -> list[BenchResult]:
    """Runs the arm suite.

    Args:
        quick: 3 segments per link, a 1 s move in a 1.2 s record, one MuJoCo step.

    Returns:
        The 10 s case against MuJoCo, then the cost for 10, 30 and 100 segments per link.
    """
    if quick:
        return [against_mujoco(3, 1.0, 1.2, repeat=1, tries=1), scaling(6, 1.0, 1.2)]
    results = [against_mujoco(10, MOVE_S, 10.0, repeat=5)]
    results += [scaling(n, MOVE_S, 10.0) for n in (10, 30, 100)]
    return results
