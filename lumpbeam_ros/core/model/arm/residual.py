"""Residual vibration after a move: how far the tip rings about where it should come to rest.

The measure is the RMS of the tip's distance from its final rest position (the static
equilibrium at the move's final joint angles, B.16 without motion) over a window that opens
when the commanded move ends: 3 s by default. It is what input shaping is judged by: a shaped
move ends later (by the shaper's duration), and its window opens at its own end.
"""

from __future__ import annotations

import math

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.simulate import ArmMotion
from lumpbeam_ros.core.model.arm.statics import arm_equilibrium

#: Length of the window after the move over which the residual vibration is taken, s.
WINDOW_S = 3.0


def rest_tip(model: ArmModel, q: np.ndarray) -> tuple[float, float]:
    """The tip's ``(x, z)`` in beam_base at rest with the joints held at ``q``, m."""
    x, z, _ = model.chain.tip_pose(arm_equilibrium(model, q))
    return float(x), float(z)


def residual_rms(
    t: np.ndarray,
    tip_x: np.ndarray,
    tip_z: np.ndarray,
    rest: tuple[float, float],
    move_end_s: float,
    window_s: float = WINDOW_S,
) -> float:
    """RMS of the tip's distance from ``rest`` over ``[move_end_s, move_end_s + window_s]``.

    Args:
        t: Sample times, s, increasing (evenly spaced: each sample weighs the same).
        tip_x: Tip x at those times, m.
        tip_z: Tip z, m.
        rest: The final rest position ``(x, z)``, m.
        move_end_s: When the commanded move ends, s.
        window_s: The window's length, s (> 0).

    Returns:
        The RMS distance, m.

    Raises:
        LumpbeamError: Series of different lengths, a window that is not positive, or samples
            that do not cover the window (to within half a sample interval).
    """
    t = np.asarray(t, dtype=float)
    x = np.asarray(tip_x, dtype=float)
    z = np.asarray(tip_z, dtype=float)
    if t.ndim != 1 or x.shape != t.shape or z.shape != t.shape or t.size < 2:
        raise LumpbeamError(
            f'residual vibration: {t.size} times for {x.size} x and {z.size} z samples'
        )
    if not (math.isfinite(window_s) and window_s > 0.0):
        raise LumpbeamError(f'residual vibration: the window must be positive, got {window_s!r}')
    end = move_end_s + window_s
    slack = 0.5 * float(np.median(np.diff(t)))
    if not (t[0] <= move_end_s + slack and t[-1] >= end - slack):
        raise LumpbeamError(
            f'residual vibration: samples from {t[0]:.6g} s to {t[-1]:.6g} s do not cover '
            f'the window {move_end_s:.6g} s to {end:.6g} s'
        )
    inside = (t >= move_end_s - 1e-9) & (t <= end + 1e-9)
    distance = np.hypot(x[inside] - rest[0], z[inside] - rest[1])
    return float(np.sqrt(np.mean(distance**2)))


def arm_residual(
    model: ArmModel, motion: ArmMotion, move_end_s: float, window_s: float = WINDOW_S
) -> float:
    """:func:`residual_rms` of a simulated motion about the rest at its last joint angles.

    Args:
        model: The arm that was simulated.
        motion: The simulation (:func:`~lumpbeam_ros.core.model.arm.simulate.simulate_arm`), its
            last sample at or after the window's end, the joints by then at their final angles.
        move_end_s: When the commanded move ends, s.
        window_s: The window's length, s.

    Returns:
        The RMS distance, m.

    Raises:
        LumpbeamError: As :func:`residual_rms`.
    """
    rest = rest_tip(model, motion.q[-1])
    return residual_rms(motion.t, motion.tip_x, motion.tip_z, rest, move_end_s, window_s)
