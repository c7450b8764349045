"""Residual vibration left by a shaped command: the shaper's sensitivity curve.

A damped second-order mode (natural frequency ``omega``, damping ratio ``zeta``) driven by the
impulses ``A_i`` at ``t_i`` rings after the last impulse with an amplitude ``V`` times that
of a single unit impulse (Singer and Seering, 1990, "Preshaping command inputs to reduce
system vibration", J. Dyn. Sys. Meas. Control 112(1)):

    V = exp(-zeta omega t_N) sqrt(C^2 + S^2),
    C = sum_i A_i exp(zeta omega t_i) cos(omega_d t_i),
    S = sum_i A_i exp(zeta omega t_i) sin(omega_d t_i),  omega_d = omega sqrt(1 - zeta^2).

The same ratio holds for any command convolved with the impulses (a step, a ramp, a smooth
move): ``V`` is the fraction of the unshaped command's residual vibration that remains, the
unshaped command taken as issued at the last impulse's time (at once, the ratio is
``exp(zeta omega t_N)`` times larger: 1.13 for zeta = 0.02 and a ZVD shaper).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import brentq

from lumpbeam_ros.core.shaping.impulses import Impulses, Mode

#: Frequencies scanned for the insensitivity band, as multiples of the design frequency.
_BAND_SCAN = np.linspace(0.05, 4.0, 7901)


def residual_vibration(
    impulses: Impulses, frequency_hz: ArrayLike, damping_ratio: float
) -> NDArray[np.float64]:
    """The fraction ``V`` of vibration left in a mode (1: as unshaped, 0: none).

    Args:
        impulses: The shaper.
        frequency_hz: The mode's undamped natural frequency (a number or an array), Hz.
        damping_ratio: The mode's damping ratio, in [0, 1).

    Returns:
        ``V`` with the shape of ``frequency_hz``.
    """
    omega = 2.0 * math.pi * np.asarray(frequency_hz, dtype=float)[..., np.newaxis]
    t = impulses.time_s - impulses.time_s[0]
    decay = np.exp(damping_ratio * omega * (t - t[-1]))
    phase = omega * math.sqrt(1.0 - damping_ratio**2) * t
    c = np.sum(impulses.amplitude * decay * np.cos(phase), axis=-1)
    s = np.sum(impulses.amplitude * decay * np.sin(phase), axis=-1)
    return np.asarray(np.hypot(c, s), dtype=float)


def insensitivity_band(impulses: Impulses, mode: Mode, tolerance: float) -> tuple[float, float]:
    """The frequencies around a mode's where the vibration left stays within a tolerance.

    Args:
        impulses: The shaper.
        mode: The mode it was designed for (its damping ratio is kept along the band).
        tolerance: Largest fraction ``V`` accepted, e.g. 0.05.

    Returns:
        The band's ends ``(low_hz, high_hz)``: scanned from 0.05 to 4 times the mode's
        frequency (an end beyond the scan is reported at its edge), then each found by root
        finding; ``(nan, nan)`` when ``V`` exceeds the tolerance at the mode's frequency.
    """
    f = mode.frequency_hz
    limit = tolerance * (1.0 + 1e-9)  # an EI shaper has V equal to the tolerance at f

    def excess(ratio: float) -> float:
        return float(residual_vibration(impulses, ratio * f, mode.damping_ratio)) - limit

    if excess(1.0) > 0.0:
        return math.nan, math.nan
    above = residual_vibration(impulses, _BAND_SCAN * f, mode.damping_ratio) > limit
    centre = int(np.searchsorted(_BAND_SCAN, 1.0))
    low = np.flatnonzero(above[:centre])
    high = np.flatnonzero(above[centre:]) + centre
    # Each end lies between the last scanned point outside the band and the next one in it.
    low_end = (
        brentq(excess, _BAND_SCAN[low[-1]], _BAND_SCAN[low[-1] + 1]) if low.size else _BAND_SCAN[0]
    )
    high_end = (
        brentq(excess, _BAND_SCAN[high[0] - 1], _BAND_SCAN[high[0]])
        if high.size
        else _BAND_SCAN[-1]
    )
    return float(low_end * f), float(high_end * f)


#: Relative frequency error at which :func:`vibration_summary` reports the vibration left.
FREQUENCY_ERROR = 0.15


def vibration_summary(impulses: Impulses, mode: Mode, tolerance: float = 0.05) -> dict[str, Any]:
    """What a shaper leaves of a mode's vibration: at the mode, 15 % off, and the band.

    Args:
        impulses: The shaper.
        mode: One of the modes it was designed for.
        tolerance: The vibration accepted in the band, fraction.

    Returns:
        ``natural_frequency_hz``, ``damping_ratio``, ``vibration_left`` (fraction ``V`` at
        the mode), ``vibration_left_15pct_low`` and ``_high`` (at 0.85 and 1.15 times its
        frequency), ``band_hz`` (``[low, high]`` where ``V <= tolerance``) and
        ``band_tolerance``.
    """
    f = mode.frequency_hz
    left = residual_vibration(
        impulses, [f, f * (1 - FREQUENCY_ERROR), f * (1 + FREQUENCY_ERROR)], mode.damping_ratio
    )
    return {
        'natural_frequency_hz': f,
        'damping_ratio': mode.damping_ratio,
        'vibration_left': float(left[0]),
        'vibration_left_15pct_low': float(left[1]),
        'vibration_left_15pct_high': float(left[2]),
        'band_hz': list(insensitivity_band(impulses, mode, tolerance)),
        'band_tolerance': tolerance,
    }
