"""A mode to cancel, and an impulse sequence (a shaper) to convolve a command with."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from lumpbeam_ros.base.errors import LumpbeamError


@dataclass(frozen=True)
class Mode:
    """A vibration mode: a damped second-order system.

    Attributes:
        frequency_hz: Undamped natural frequency, Hz (finite, > 0).
        damping_ratio: Damping ratio (finite, in [0, 1): underdamped).

    Raises:
        LumpbeamError: A frequency that is not a positive finite number, or a damping ratio
            outside [0, 1).
    """

    frequency_hz: float
    damping_ratio: float

    def __post_init__(self) -> None:
        if not (math.isfinite(self.frequency_hz) and self.frequency_hz > 0.0):
            raise LumpbeamError(
                f'natural frequency must be a positive number of Hz, got {self.frequency_hz!r}'
            )
        if not (math.isfinite(self.damping_ratio) and 0.0 <= self.damping_ratio < 1.0):
            raise LumpbeamError(
                f'damping ratio must be in [0, 1) (an underdamped mode), '
                f'got {self.damping_ratio!r}'
            )

    @property
    def damped_period_s(self) -> float:
        """Period of the damped oscillation, ``1 / (f sqrt(1 - zeta^2))``, s."""
        return 1.0 / (self.frequency_hz * math.sqrt(1.0 - self.damping_ratio**2))


@dataclass(frozen=True, eq=False)
class Impulses:
    """An impulse sequence: the command is replaced by ``sum_i A_i u(t - t_i)``.

    Attributes:
        time_s: Impulse times (k,), s: the first at 0, increasing.
        amplitude: Impulse amplitudes (k,), positive, summing to 1 (so the command ends
            where the unshaped one does).
    """

    time_s: NDArray[np.float64]
    amplitude: NDArray[np.float64]

    def __post_init__(self) -> None:
        time = np.array(self.time_s, dtype=float)
        amplitude = np.array(self.amplitude, dtype=float)
        if time.ndim != 1 or time.shape != amplitude.shape or time.size == 0:
            raise ValueError(f'impulses: {time.shape} times for {amplitude.shape} amplitudes')
        time.setflags(write=False)
        amplitude.setflags(write=False)
        object.__setattr__(self, 'time_s', time)
        object.__setattr__(self, 'amplitude', amplitude)

    @property
    def duration_s(self) -> float:
        """Time from the first impulse to the last: how much later a shaped command ends."""
        return float(self.time_s[-1] - self.time_s[0])

    def convolve(self, other: Impulses) -> Impulses:
        """The sequence that applies both shapers (each impulse of one times each of the other).

        Impulses that fall at the same time (to 1e-12 s) are merged.
        """
        times = np.add.outer(self.time_s, other.time_s).ravel()
        amplitudes = np.multiply.outer(self.amplitude, other.amplitude).ravel()
        _, first, index = np.unique(np.round(times, 12), return_index=True, return_inverse=True)
        summed = np.bincount(index.ravel(), weights=amplitudes)
        return Impulses(times[first], summed / summed.sum())

    def as_list(self) -> list[dict[str, float]]:
        """The JSON form: a list of ``{time_s, amplitude}``."""
        return [
            {'time_s': float(t), 'amplitude': float(a)}
            for t, a in zip(self.time_s, self.amplitude, strict=True)
        ]
