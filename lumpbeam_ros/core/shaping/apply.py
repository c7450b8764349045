"""A joint trajectory shaped: the commanded angles convolved with a shaper's impulses.

The shaped command is ``u_s(t) = sum_i A_i u(t - t_i)``. The trajectory is linear between
its samples and held outside them, so each term is the input linearly interpolated at
shifted times: a sum over the few impulses replaces a full convolution. When the input is
evenly sampled at 1 kHz or finer, the output keeps its grid and each shifted copy is a
weighted sum of two row slices of the input (a fractional delay, exact for linear
interpolation); otherwise each is one ``np.interp`` per joint.
"""

from __future__ import annotations

import math

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.shaping.impulses import Impulses

#: Coarsest sample interval of a shaped trajectory (1 kHz), s.
MAX_STEP_S = 1e-3

#: Most samples a shaped trajectory may have (about 2.8 h at 1 kHz).
MAX_SAMPLES = 10_000_000

#: Relative spread of the intervals below which samples count as evenly spaced.
_EVEN = 1e-9


def _even_step(time: np.ndarray) -> float | None:
    """The sample interval of evenly spaced times, else ``None``."""
    step = float(time[-1] - time[0]) / (time.size - 1)
    return step if float(np.max(np.abs(np.diff(time) - step))) <= _EVEN * step else None


def _count(span_s: float, step_s: float) -> int:
    """Samples at ``step_s`` (the last interval possibly shorter) over ``span_s``."""
    count = math.ceil(span_s / step_s * (1.0 - 1e-12)) + 1
    if count > MAX_SAMPLES:
        raise LumpbeamError(
            f'the shaped trajectory would have {count} samples ({span_s:.6g} s at '
            f'{1.0 / step_s:.6g} Hz), more than {MAX_SAMPLES}: is the frequency too low?'
        )
    return count


def shaped_times(trajectory: JointTrajectory, added_s: float) -> np.ndarray:
    """The sample times of the shaped trajectory.

    From the input's first time to its last plus ``added_s`` (the shapers' duration). An
    input evenly sampled at 1 kHz or finer keeps its grid (the last interval may be shorter,
    to end on the last time); any other input gives evenly spaced times at 1 kHz, or at the
    input's median interval if finer.

    Raises:
        LumpbeamError: The shaped trajectory would exceed :data:`MAX_SAMPLES` samples.
    """
    start = float(trajectory.time_s[0])
    span = trajectory.duration_s + added_s
    step = _even_step(trajectory.time_s)
    if step is not None and step <= MAX_STEP_S:
        times = start + np.arange(_count(span, step)) * step
        times[-1] = start + span
        return times
    step = min(MAX_STEP_S, float(np.median(np.diff(trajectory.time_s))))
    return np.linspace(start, start + span, _count(span, step))


def _delayed_sum(angles: np.ndarray, step: float, count: int, impulses: Impulses) -> np.ndarray:
    """``sum_i A_i u(k step - t_i)`` for ``k < count`` on the input's own even grid."""
    shift = (impulses.time_s - impulses.time_s[0]) / step
    whole = np.floor(shift).astype(int)
    fraction = shift - whole
    # The input held at its first row before it and at its last after it.
    left = int(whole.max()) + 1
    right = max(0, count - angles.shape[0]) + 1
    padded = np.concatenate(
        [np.repeat(angles[:1], left, axis=0), angles, np.repeat(angles[-1:], right, axis=0)]
    )
    shaped = np.zeros((count, angles.shape[1]))
    for m, f, a in zip(whole, fraction, impulses.amplitude, strict=True):
        at = padded[left - m : left - m + count]  # u at k - m
        before = padded[left - m - 1 : left - m - 1 + count]  # u at k - m - 1
        shaped += a * (at + f * (before - at))
    return shaped


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
    times = shaped_times(trajectory, impulses.duration_s)
    step = _even_step(trajectory.time_s)
    delay = impulses.time_s - impulses.time_s[0]
    if step is not None and step <= MAX_STEP_S:
        shaped = _delayed_sum(trajectory.angles_rad, step, times.size, impulses)
    else:
        shaped = np.zeros((times.size, trajectory.joint_count))
        for j, angles in enumerate(trajectory.angles_rad.T):
            for t_i, a_i in zip(delay, impulses.amplitude, strict=True):
                shaped[:, j] += a_i * np.interp(times - t_i, trajectory.time_s, angles)
    # Where every delayed copy is at rest the sum is the input's angle times the amplitudes'
    # sum, 1 only up to round-off: a move to 0.5 rad would end at 0.4999999999999999.
    start, end = trajectory.time_s[0], trajectory.time_s[-1] + delay[-1]
    shaped[times <= start] = trajectory.angles_rad[0]
    shaped[times >= end - 1e-9 * max(1.0, abs(end))] = trajectory.angles_rad[-1]
    return JointTrajectory(times, shaped, trajectory.joint_names)
