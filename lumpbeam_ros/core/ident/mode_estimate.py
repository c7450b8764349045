"""One damped mode's frequency, damping ratio and decrement, with standard deviations.

A mode ``A e^{-sigma tau} cos(omega_d tau + phi)`` is parametrised as
``e^{-sigma tau} (a cos(omega_d tau) + b sin(omega_d tau))``. The derived figures follow the
paper's definitions: the logarithmic decrement is the decay over one damped period, so that
B.21 holds, ``zeta = 1 / sqrt(1 + (2 pi / delta)^2)``; the natural frequency is
``f_n = f_d / sqrt(1 - zeta^2)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from lumpbeam_ros.core.ident.covariance import propagate

TWO_PI = 2.0 * math.pi


def damping_ratio_from_decrement(log_decrement: float) -> float:
    """The paper's damping ratio from the log decrement, ``1 / sqrt(1 + (2 pi/delta)^2)`` (B.21).

    Args:
        log_decrement: delta of B.20.

    Returns:
        zeta (NaN when delta is not positive).
    """
    if not log_decrement > 0.0:
        return float('nan')
    return 1.0 / math.sqrt(1.0 + (TWO_PI / log_decrement) ** 2)


@dataclass(frozen=True)
class ModeEstimate:
    """A damped mode with first-order standard deviations (NaN when not known).

    Attributes:
        damped_frequency_hz: f_d = omega_d / (2 pi).
        natural_frequency_hz: f_n = sqrt(sigma^2 + omega_d^2) / (2 pi) = f_d / sqrt(1-zeta^2).
        damping_ratio: zeta = sigma / omega_n.
        log_decrement: delta = sigma T_d = 2 pi sigma / omega_d (B.20 for a pure decay).
        decay_rate: sigma = zeta omega_n, 1/s.
        amplitude: A at the start of the fitted stretch.
    """

    damped_frequency_hz: float
    natural_frequency_hz: float
    damping_ratio: float
    log_decrement: float
    decay_rate: float
    amplitude: float
    damped_frequency_hz_std: float = float('nan')
    natural_frequency_hz_std: float = float('nan')
    damping_ratio_std: float = float('nan')
    log_decrement_std: float = float('nan')
    decay_rate_std: float = float('nan')
    amplitude_std: float = float('nan')

    @property
    def damped_omega(self) -> float:
        """omega_d, rad/s."""
        return TWO_PI * self.damped_frequency_hz

    @classmethod
    def from_parameters(
        cls,
        cos_amp: float,
        sin_amp: float,
        decay_rate: float,
        damped_omega: float,
        covariance: np.ndarray | None = None,
    ) -> ModeEstimate:
        """Derives the mode figures from ``(a, b, sigma, omega_d)`` and their covariance.

        Args:
            cos_amp: a.
            sin_amp: b.
            decay_rate: sigma, 1/s.
            damped_omega: omega_d, rad/s.
            covariance: 4 x 4 covariance of ``(a, b, sigma, omega_d)``, or ``None``.

        Returns:
            The mode.
        """
        a, b, s, w = cos_amp, sin_amp, decay_rate, damped_omega
        wn = math.hypot(s, w)
        amp = math.hypot(a, b)
        values = {
            'damped_frequency_hz': w / TWO_PI,
            'natural_frequency_hz': wn / TWO_PI,
            'damping_ratio': s / wn,
            'log_decrement': TWO_PI * s / w,
            'decay_rate': s,
            'amplitude': amp,
        }
        if covariance is None:
            return cls(**values)
        grads = {
            'damped_frequency_hz': [0.0, 0.0, 0.0, 1.0 / TWO_PI],
            'natural_frequency_hz': [0.0, 0.0, s / (wn * TWO_PI), w / (wn * TWO_PI)],
            'damping_ratio': [0.0, 0.0, w * w / wn**3, -s * w / wn**3],
            'log_decrement': [0.0, 0.0, TWO_PI / w, -TWO_PI * s / w**2],
            'decay_rate': [0.0, 0.0, 1.0, 0.0],
            'amplitude': [a / amp, b / amp, 0.0, 0.0] if amp > 0 else [0.0] * 4,
        }
        stds = {f'{name}_std': propagate(np.asarray(g), covariance) for name, g in grads.items()}
        return cls(**values, **stds)
