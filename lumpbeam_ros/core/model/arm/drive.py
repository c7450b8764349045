"""Prescribed joint motions: what the servos make the joints do, with its rates.

A sampled trajectory (a trajectory file's rows) moves linearly between samples and holds
its first and last rows outside them, so its rate is the slope of the current interval and
jumps at each sample (:class:`SampledMotion`). A smooth motion given by functions of time
(:class:`SmoothMotion`) supplies its own rates.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np
from scipy.interpolate import CubicSpline, PPoly

from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory


class JointMotion(Protocol):
    """Joint angles and their rates as functions of time."""

    @property
    def n_joints(self) -> int:
        """Number of joints."""
        ...

    @property
    def knots(self) -> np.ndarray:
        """Times where the rates jump (an integrator steps onto them), s; may be empty."""
        ...

    @property
    def end_time(self) -> float:
        """When the motion stops for good, s."""
        ...

    def angles(self, t: float) -> np.ndarray:
        """Joint angles at ``t``, rad, shape (n_joints,)."""
        ...

    def rates(self, t: float) -> np.ndarray:
        """Joint rates at ``t``, rad/s, shape (n_joints,)."""
        ...

    def sample(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Angles, rates and accelerations at many times, each (len(times), n_joints)."""
        ...


#: Two samples this close (times the angle, above 1 rad) are a hold, rad.
HOLD_TOLERANCE_RAD = 1e-12
#: Step of the central difference that gives a smooth motion's accelerations from its rates, s.
_DIFFERENCE_STEP_S = 1e-6


class SampledMotion:
    """A joint trajectory file's motion: linear between samples, the ends held.

    Args:
        trajectory: The samples (validated by
            :class:`~lumpbeam_ros.core.model.arm.joint_trajectory.JointTrajectory`).
    """

    def __init__(self, trajectory: JointTrajectory):
        self.trajectory = trajectory
        self.time_s = trajectory.time_s
        self.angles_rad = trajectory.angles_rad
        slopes = np.diff(self.angles_rad, axis=0) / np.diff(self.time_s)[:, None]
        zero = np.zeros((1, self.angles_rad.shape[1]))
        # Interval i (before sample 0, between samples, after the last) has slope _slopes[i].
        self._slopes = np.vstack([zero, slopes, zero])

    @classmethod
    def from_arrays(cls, time_s: np.ndarray, angles_rad: np.ndarray) -> SampledMotion:
        """From sample times (m,) and angles (m, n_joints) or (m,) for one joint.

        Raises:
            LumpbeamError: As
                :class:`~lumpbeam_ros.core.model.arm.joint_trajectory.JointTrajectory`.
        """
        return cls(JointTrajectory(time_s, angles_rad))

    @property
    def n_joints(self) -> int:
        """Number of joints."""
        return int(self.angles_rad.shape[1])

    @property
    def knots(self) -> np.ndarray:
        """The sample times."""
        return self.time_s

    @property
    def end_time(self) -> float:
        """The last sample's time."""
        return float(self.time_s[-1])

    def angles(self, t: float) -> np.ndarray:
        """Linear interpolation, the ends held."""
        i = int(np.searchsorted(self.time_s, t, side='right'))
        if i == 0:
            return np.asarray(self.angles_rad[0].copy())
        return np.asarray(self.angles_rad[i - 1] + self._slopes[i] * (t - self.time_s[i - 1]))

    def rates(self, t: float) -> np.ndarray:
        """The slope of the interval holding ``t`` (at a sample: of the one after it)."""
        return np.asarray(self._slopes[int(np.searchsorted(self.time_s, t, side='right'))])

    def sample(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`angles` and :meth:`rates` at many times; no acceleration between samples."""
        times = np.asarray(times, dtype=float)
        index = np.searchsorted(self.time_s, times, side='right')
        before = np.maximum(index - 1, 0)
        offset = np.where(index > 0, times - self.time_s[before], 0.0)
        slopes = self._slopes[index]
        angles = self.angles_rad[before] + slopes * offset[:, None]
        return angles, slopes, np.zeros_like(angles)

    def spline(self) -> SmoothMotion:
        """The smooth motion the samples stand for: their cubic spline, the holds kept still.

        Densely sampled smooth motion (1 kHz or finer) is what a trajectory file holds; the
        spline differs from the straight lines between samples by at most ``q'' h^2 / 8``
        (about 1e-6 rad for 10 rad/s^2 at 1 kHz) and from the sampled motion itself by
        ``O(h^4)``, and its rates do not jump at every sample. A hold (two samples with the
        same angles) stays still: each stretch of motion between holds is splined on its own,
        at rest where it meets a hold. One spline through everything would wiggle the joints
        during a hold, more the shorter it is (0.6 mrad in a 0.3 s hold before a 1 kHz
        move), and the wiggle would change whenever samples were added after it.
        A stretch of one interval stays a straight line, its rate jumping at both ends.
        """
        if self.time_s.size < 3:
            return SmoothMotion(self.angles, self.rates, self.n_joints, self.end_time)
        coefficients, corners = _piecewise_cubic(self.time_s, self.angles_rad)
        polynomial = PPoly(coefficients, self.time_s)
        start, end = float(self.time_s[0]), self.end_time

        def derivative(order: int) -> Callable[[float], np.ndarray]:
            # Array times give arrays of rows: the polynomial is evaluated once for all.
            def at(t: float) -> np.ndarray:
                inside = (np.asarray(t) >= start) & (np.asarray(t) <= end)
                value = polynomial(np.clip(t, start, end), order)
                return np.asarray(value if order == 0 else np.where(inside[..., None], value, 0.0))

            return at

        return SmoothMotion(
            derivative(0),
            derivative(1),
            self.n_joints,
            end,
            corners,
            derivative(2),
            vectorized=True,
        )


def _piecewise_cubic(time_s: np.ndarray, angles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The coefficients of :meth:`SampledMotion.spline` on each interval, and its corners.

    Returns:
        ``PPoly`` coefficients (4, intervals, joints) on the sample times, and the times
        where the rates jump (the ends, and both ends of a lone moving interval), s.
    """
    steps = np.diff(angles, axis=0)
    slopes = steps / np.diff(time_s)[:, None]
    coefficients = np.zeros((4, time_s.size - 1, angles.shape[1]))
    coefficients[2], coefficients[3] = slopes, angles[:-1]  # straight lines and holds
    # A hold computed by sums (a shaped command's, its amplitudes adding up to 1 within
    # rounding) moves by ulps: still a hold.
    still = HOLD_TOLERANCE_RAD * np.maximum(1.0, np.abs(angles[:-1]))
    moving = np.any(np.abs(steps) > still, axis=1)
    edges = np.flatnonzero(np.diff(np.concatenate([[False], moving, [False]]).astype(int)))
    corners = [time_s[0], time_s[-1]]
    at_rest = (1, np.zeros(angles.shape[1]))
    for first, stop in zip(edges[::2], edges[1::2], strict=True):
        if stop - first == 1:
            corners += [time_s[first], time_s[stop]]
            continue
        left = at_rest if first > 0 else 'not-a-knot'
        right = at_rest if stop < time_s.size - 1 else 'not-a-knot'
        spline = CubicSpline(
            time_s[first : stop + 1], angles[first : stop + 1], axis=0, bc_type=(left, right)
        )
        coefficients[:, first:stop] = spline.c
    return coefficients, np.unique(corners)


@dataclass(frozen=True)
class SmoothMotion:
    """A motion given by functions of time.

    Attributes:
        angle_function: ``t -> q(t)``, rad.
        rate_function: ``t -> q'(t)``, rad/s.
        n_joints: Number of joints.
        end_time: When the motion stops for good, s (the ring-down after it is free
            vibration); infinite by default.
        corners: Times where the rates jump, s.
        acceleration_function: ``t -> q''(t)``, rad/s^2; ``None``: the central difference
            of ``rate_function`` over 1e-6 s (its error, ``q^(4) 1e-12 / 6``, is far below
            anything simulated).
        vectorized: The functions take an array of times and return one row per time.
    """

    angle_function: Callable[[float], np.ndarray]
    rate_function: Callable[[float], np.ndarray]
    n_joints: int
    end_time: float = math.inf
    corners: np.ndarray = field(default_factory=lambda: np.zeros(0))
    acceleration_function: Callable[[float], np.ndarray] | None = None
    vectorized: bool = False

    @property
    def knots(self) -> np.ndarray:
        """The corners given (where the rates jump; none by default)."""
        return self.corners

    def angles(self, t: float) -> np.ndarray:
        """``angle_function(t)``."""
        return np.asarray(self.angle_function(t), dtype=float)

    def rates(self, t: float) -> np.ndarray:
        """``rate_function(t)``."""
        return np.asarray(self.rate_function(t), dtype=float)

    def accelerations(self, t: float) -> np.ndarray:
        """``acceleration_function(t)``, or the central difference of the rates."""
        if self.acceleration_function is not None:
            return np.asarray(self.acceleration_function(t), dtype=float)
        step = _DIFFERENCE_STEP_S
        return np.asarray((self.rates(t + step) - self.rates(t - step)) / (2.0 * step))

    def sample(self, times: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Angles, rates and accelerations at many times, each (len(times), n_joints)."""
        times = np.asarray(times, dtype=float)
        if self.vectorized:
            at: Any = times
            return self.angles(at), self.rates(at), self.accelerations(at)
        rows = [(self.angles(t), self.rates(t), self.accelerations(t)) for t in times.tolist()]
        shape = (times.size, self.n_joints)
        q, q_dot, q_ddot = (np.array([row[i] for row in rows]).reshape(shape) for i in range(3))
        return q, q_dot, q_ddot
