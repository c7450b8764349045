"""Prescribed joint motions: what the servos make the joints do, with its rates.

A sampled trajectory (a trajectory file's rows) moves linearly between samples and holds
its first and last rows outside them, so its rate is the slope of the current interval and
jumps at each sample (:class:`SampledMotion`). A smooth motion given by functions of time
(:class:`SmoothMotion`) supplies its own rates.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from lumpbeam_ros.errors import LumpbeamError


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


@dataclass(frozen=True)
class SampledMotion:
    """Joint angles sampled in time, linear in between, held outside.

    Attributes:
        time_s: Sample times, strictly increasing, shape (m,).
        angles_rad: Angles, shape (m, n_joints).
    """

    time_s: np.ndarray
    angles_rad: np.ndarray
    _slopes: np.ndarray = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        t = np.asarray(self.time_s, dtype=float)
        q = np.asarray(self.angles_rad, dtype=float)
        if q.ndim == 1:
            q = q[:, None]
        if t.ndim != 1 or q.ndim != 2 or q.shape[0] != t.size or t.size == 0:
            raise LumpbeamError(f'joint motion: {t.size} times for {q.shape[0]} rows of angles')
        if not (np.all(np.isfinite(t)) and np.all(np.isfinite(q))):
            raise LumpbeamError('joint motion: times and angles must be finite')
        if np.any(np.diff(t) <= 0.0):
            raise LumpbeamError('joint motion: times must increase strictly')
        object.__setattr__(self, 'time_s', t)
        object.__setattr__(self, 'angles_rad', q)
        slopes = np.diff(q, axis=0) / np.diff(t)[:, None]
        zero = np.zeros((1, q.shape[1]))
        # Interval i (before sample 0, between samples, after the last) has slope _slopes[i].
        object.__setattr__(self, '_slopes', np.vstack([zero, slopes, zero]))

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
        return np.array([np.interp(t, self.time_s, column) for column in self.angles_rad.T])

    def rates(self, t: float) -> np.ndarray:
        """The slope of the interval holding ``t`` (at a sample: of the one after it)."""
        return np.asarray(self._slopes[int(np.searchsorted(self.time_s, t, side='right'))])


@dataclass(frozen=True)
class SmoothMotion:
    """A motion given by functions of time.

    Attributes:
        angle_function: ``t -> q(t)``, rad.
        rate_function: ``t -> q'(t)``, rad/s.
        n_joints: Number of joints.
        end_time: When the motion stops, s (the ring-down after it is free vibration).
    """

    angle_function: Callable[[float], np.ndarray]
    rate_function: Callable[[float], np.ndarray]
    n_joints: int
    end_time: float = 0.0

    @property
    def knots(self) -> np.ndarray:
        """None: the rates are continuous."""
        return np.zeros(0)

    def angles(self, t: float) -> np.ndarray:
        """``angle_function(t)``."""
        return np.asarray(self.angle_function(t), dtype=float)

    def rates(self, t: float) -> np.ndarray:
        """``rate_function(t)``."""
        return np.asarray(self.rate_function(t), dtype=float)
