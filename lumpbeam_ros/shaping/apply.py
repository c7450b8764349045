"""A joint trajectory shaped: the commanded angles convolved with a shaper's impulses.

The shaped command is ``u_s(t) = sum_i A_i u(t - t_i)``. The trajectory is linear between
its samples and held outside them, so each term is one linear interpolation of the input at
shifted times: a sum over the few impulses replaces a full convolution.
"""

from __future__ import annotations

import math

import numpy as np

from lumpbeam_ros.errors import LumpbeamError
from lumpbeam_ros.motion.joint_trajectory import JointTrajectory
from lumpbeam_ros.shaping.impulses import Impulses

#: Coarsest sample interval of a shaped trajectory (1 kHz), s.
MAX_STEP_S = 1e-3

#: Most samples a shaped trajectory may have (about 2.8 h at 1 kHz).
MAX_SAMPLES = 10_000_000


def shaped_times(trajectory: JointTrajectory, impulses: Impulses) -> np.ndarray:
    """The sample times of the shaped trajectory.

    Evenly spaced from the input's first time to its last plus the shaper's duration, at
    1 kHz or at the input's own rate (its median interval) if finer.

    Raises:
        LumpbeamError: The shaped trajectory would exceed :data:`MAX_SAMPLES` samples.
    """
    step = min(MAX_STEP_S, float(np.median(np.diff(trajectory.time_s))))
    start = float(trajectory.time_s[0])
    end = float(trajectory.time_s[-1]) + impulses.duration_s
    count = math.ceil((end - start) / step * (1.0 - 1e-12)) + 1
    if count > MAX_SAMPLES:
        raise LumpbeamError(
            f'the shaped trajectory would have {count} samples ({end - start:.6g} s at '
            f'{1.0 / step:.6g} Hz), more than {MAX_SAMPLES}: is the frequency too low?'
        )
    return np.linspace(start, end, count)


def shape_trajectory(trajectory: JointTrajectory, impulses: Impulses) -> JointTrajectory:
    """Convolves a joint trajectory with a shaper.

    Args:
        trajectory: The commanded trajectory (linear between samples).
        impulses: The shaper (amplitudes summing to 1).

    Returns:
        The shaped trajectory, with the same joint names, sampled by :func:`shaped_times`:
        it starts where the input starts and ends ``impulses.duration_s`` later, at rest at
        the input's last angles.

    Raises:
        LumpbeamError: The shaped trajectory would be too long (see :func:`shaped_times`).
    """
    times = shaped_times(trajectory, impulses)
    delay = impulses.time_s - impulses.time_s[0]
    shaped = np.empty((times.size, trajectory.joint_count))
    for j, angles in enumerate(trajectory.angles_rad.T):
        column = shaped[:, j]
        column[:] = impulses.amplitude[0] * np.interp(times - delay[0], trajectory.time_s, angles)
        for t_i, a_i in zip(delay[1:], impulses.amplitude[1:], strict=True):
            column += a_i * np.interp(times - t_i, trajectory.time_s, angles)
    return JointTrajectory(times, shaped, trajectory.joint_names)
