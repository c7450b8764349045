"""The extra-insensitive (EI) shaper of a damped mode, solved from its defining constraints.

Singhose, Seering and Singer (1994, "Residual vibration reduction using vector diagrams to
generate shaping inputs", J. Mech. Design 116(2)) define the three-impulse EI shaper by
letting the vibration at the design frequency rise to a tolerance ``V_tol`` instead of 0, in
exchange for a much wider band of low vibration:

- the vibration left at the design frequency is ``V_tol``, and is a local maximum there
  (``dV/domega = 0``);
- it is zero at two frequencies ``omega_l < omega < omega_h`` (same damping ratio);
- the amplitudes sum to 1.

Without damping this gives the closed form ``A = [(1 + V)/4, (1 - V)/2, (1 + V)/4]`` at
``t = [0, T/2, T]``. With damping the six equations in ``A_1, A_2, t_2, t_3, omega_l,
omega_h`` are solved numerically (Powell's hybrid method), by continuation in the damping
ratio from that closed form; ``V`` is the residual vibration of
:mod:`lumpbeam_ros.core.shaping.vibration` (Singer and Seering, 1990).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import root

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.shaping.impulses import Impulses, Mode

#: The vibration tolerance of the EI shaper: 5 % of the unshaped vibration.
EI_TOLERANCE = 0.05

#: Largest damping ratio the EI shaper is solved for. Flexible links are lightly damped
#: (a few percent); beyond this the amplitudes collapse onto the first impulse and the
#: ZVD shaper is the robust choice.
EI_MAX_DAMPING = 0.5

#: Largest step in damping ratio between two solves of the continuation.
_STEP = 0.05


def _residual_parts(
    amplitude: NDArray[np.float64], t: NDArray[np.float64], omega: float, zeta: float
) -> tuple[float, float, float, float]:
    """The residual vibration's ``C`` and ``S`` and their derivatives in ``omega``.

    Both are scaled by ``exp(-zeta omega t_N)``, so that their norm is ``V``.
    """
    root_1 = math.sqrt(1.0 - zeta * zeta)
    decay = amplitude * np.exp(zeta * omega * (t - t[-1]))
    cos = np.cos(omega * root_1 * t)
    sin = np.sin(omega * root_1 * t)
    lag = zeta * (t - t[-1])
    c = float(np.sum(decay * cos))
    s = float(np.sum(decay * sin))
    dc = float(np.sum(decay * (lag * cos - root_1 * t * sin)))
    ds = float(np.sum(decay * (lag * sin + root_1 * t * cos)))
    return c, s, dc, ds


def _constraints(x: NDArray[np.float64], zeta: float, tolerance: float) -> list[float]:
    """The six EI equations, in units where the design frequency is 1 rad/s."""
    a1, a2, t2, t3, omega_low, omega_high = x
    amplitude = np.array([a1, a2, 1.0 - a1 - a2])
    t = np.array([0.0, t2, t3])
    c, s, dc, ds = _residual_parts(amplitude, t, 1.0, zeta)
    c_low, s_low, _, _ = _residual_parts(amplitude, t, omega_low, zeta)
    c_high, s_high, _, _ = _residual_parts(amplitude, t, omega_high, zeta)
    return [c * c + s * s - tolerance**2, c * dc + s * ds, c_low, s_low, c_high, s_high]


@lru_cache(maxsize=64)
def _unit_solution(zeta: float, tolerance: float) -> tuple[float, ...]:
    """``(A_1, A_2, t_2, t_3)`` of the EI shaper for a 1 rad/s mode of damping ``zeta``."""
    swing = math.acos(-(1.0 - tolerance) / (1.0 + tolerance))
    x = np.array(
        [(1 + tolerance) / 4, (1 - tolerance) / 2, math.pi, 2 * math.pi, swing / math.pi]
        + [2 - swing / math.pi]
    )
    steps = max(1, math.ceil(zeta / _STEP))
    for z in np.linspace(0.0, zeta, steps + 1)[1:]:
        solved = root(_constraints, x, args=(float(z), tolerance), method='hybr', tol=1e-12)
        x = solved.x
        a3 = 1.0 - x[0] - x[1]
        valid = solved.success and min(x[0], x[1], a3) > 0.0 and 0.0 < x[2] < x[3]
        if not valid or max(abs(e) for e in _constraints(x, float(z), tolerance)) > 1e-9:
            raise LumpbeamError(f'EI shaper: no solution for damping ratio {zeta!r}')
    return tuple(float(v) for v in x[:4])


def ei_shaper(mode: Mode, tolerance: float = EI_TOLERANCE) -> Impulses:
    """The EI shaper of a mode: three impulses, vibration at most ``tolerance`` near it.

    Args:
        mode: The mode to cancel.
        tolerance: The vibration allowed at the design frequency (fraction, in (0, 0.5)).

    Returns:
        Three impulses; the last at about one damped period.

    Raises:
        LumpbeamError: The damping ratio exceeds :data:`EI_MAX_DAMPING`, or the tolerance is
            out of range.
    """
    if not 0.0 < tolerance < 0.5:
        raise LumpbeamError(
            f'EI shaper: vibration tolerance must be in (0, 0.5), got {tolerance!r}'
        )
    if mode.damping_ratio > EI_MAX_DAMPING:
        raise LumpbeamError(
            f'EI shaper: damping ratio {mode.damping_ratio!r} is above {EI_MAX_DAMPING} '
            '(use the ZVD shaper for so damped a mode)'
        )
    a1, a2, t2, t3 = _unit_solution(mode.damping_ratio, tolerance)
    omega = 2.0 * math.pi * mode.frequency_hz
    return Impulses(np.array([0.0, t2, t3]) / omega, np.array([a1, a2, 1.0 - a1 - a2]))
