"""The shapers by name (ZV, ZVD, EI), and one shaper for several modes.

ZV and ZVD are Singer and Seering's (1990, "Preshaping command inputs to reduce system
vibration", J. Dyn. Sys. Meas. Control 112(1)) closed forms for a damped mode, with
``K = exp(-zeta pi / sqrt(1 - zeta^2))`` and the damped period ``T_d``:

- ZV:  ``A = [1, K] / (1 + K)`` at ``t = [0, T_d/2]``: no vibration at the design frequency;
- ZVD: ``A = [1, 2K, K^2] / (1 + K)^2`` at ``t = [0, T_d/2, T_d]``: no vibration and a zero
  derivative with respect to frequency, so a wider band of low vibration.

EI is in :mod:`lumpbeam_ros.core.shaping.extra_insensitive`. Several modes are cancelled by
convolving their shapers (each mode's shaper leaves the others' cancellation intact).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.shaping.choices import SHAPER_NAMES
from lumpbeam_ros.core.shaping.extra_insensitive import ei_shaper
from lumpbeam_ros.core.shaping.impulses import Impulses, Mode


def _k(mode: Mode) -> float:
    zeta = mode.damping_ratio
    return math.exp(-zeta * math.pi / math.sqrt(1.0 - zeta * zeta))


def zv_shaper(mode: Mode) -> Impulses:
    """The zero-vibration shaper of a mode: two impulses, half a damped period apart."""
    k = _k(mode)
    return Impulses(np.array([0.0, mode.damped_period_s / 2]), np.array([1.0, k]) / (1.0 + k))


def zvd_shaper(mode: Mode) -> Impulses:
    """The zero-vibration-and-derivative shaper of a mode: three impulses over a period."""
    k = _k(mode)
    period = mode.damped_period_s
    return Impulses(
        np.array([0.0, period / 2, period]), np.array([1.0, 2.0 * k, k * k]) / (1.0 + k) ** 2
    )


#: The shapers by the names the command line and the node take.
SHAPERS: dict[str, Callable[[Mode], Impulses]] = dict(
    zip(SHAPER_NAMES, (zv_shaper, zvd_shaper, ei_shaper), strict=True)
)


def design_shaper(kind: str, modes: Sequence[Mode]) -> Impulses:
    """One shaper that cancels every mode given: the modes' shapers convolved.

    Args:
        kind: ``'zv'``, ``'zvd'`` or ``'ei'``, used for every mode.
        modes: The modes, at least one.

    Returns:
        The impulses (amplitudes summing to 1).

    Raises:
        LumpbeamError: An unknown kind, no mode, or a mode the shaper cannot cancel.
    """
    if kind not in SHAPERS:
        raise LumpbeamError(f'unknown shaper {kind!r} (choose from {", ".join(SHAPERS)})')
    if not modes:
        raise LumpbeamError('a shaper needs at least one mode')
    shaper = SHAPERS[kind](modes[0])
    for mode in modes[1:]:
        shaper = shaper.convolve(SHAPERS[kind](mode))
    return shaper
