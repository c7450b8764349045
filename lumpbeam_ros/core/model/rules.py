"""The paper's closed-form rules: Euler-Bernoulli statics and the lumped stiffness and damping.

Equation numbers refer to reference/paper.txt (Subedi, Tyapin, Hovland).
"""

from __future__ import annotations

import numpy as np


def uniform_load_deflection(q: float, length: float, ei: float) -> float:
    """Tip deflection of a cantilever under a uniform load, ``q L^4 / (8 EI)`` (B.1).

    Args:
        q: Load per length, N/m.
        length: Beam length L, m.
        ei: Bending stiffness EI, N m^2.

    Returns:
        The deflection, m.
    """
    return q * length**4 / (8.0 * ei)


def uniform_load_slope(q: float, length: float, ei: float) -> float:
    """Tip slope of a cantilever under a uniform load, ``q L^3 / (6 EI)`` (B.2)."""
    return q * length**3 / (6.0 * ei)


def end_load_deflection(force: float, length: float, ei: float) -> float:
    """Tip deflection of a cantilever under an end load, ``F L^3 / (3 EI)`` (B.3).

    Args:
        force: End load F, N.
        length: Beam length L, m.
        ei: Bending stiffness EI, N m^2.

    Returns:
        The deflection, m.
    """
    return force * length**3 / (3.0 * ei)


def end_load_slope(force: float, length: float, ei: float) -> float:
    """Tip slope of a cantilever under an end load, ``F L^2 / (2 EI)`` (B.4)."""
    return force * length**2 / (2.0 * ei)


def analytic_segment_stiffness(ei: float, segment_length: float) -> float:
    """Equivalent stiffness of one segment, ``k = 2 EI / L_s`` (B.6, B.9).

    Args:
        ei: Bending stiffness EI, N m^2.
        segment_length: L_s = L / n_s, m.

    Returns:
        k, N m/rad.
    """
    return 2.0 * ei / segment_length


def total_stiffness_from_deflection(force: float, length: float, deflection: float) -> float:
    """Total equivalent stiffness from a measured static deflection (B.12).

    ``k_tE = 2 F_E L^2 / (3 delta_vE)``.

    Args:
        force: Known tip load F_E, N.
        length: Beam length L, m.
        deflection: Measured change of the vertical tip position delta_vE, m (positive).

    Returns:
        k_tE, N m/rad.
    """
    return 2.0 * force * length**2 / (3.0 * deflection)


def deflection_from_total_stiffness(force: float, length: float, k_total: float) -> float:
    """The static tip deflection that B.12 assigns to a total stiffness (B.12 inverted)."""
    return 2.0 * force * length**2 / (3.0 * k_total)


def joint_stiffnesses(k: float, n_segments: int) -> np.ndarray:
    """Stiffness of every joint: ``k`` at the wall, ``k' = k / 2`` between segments (B.10).

    Args:
        k: Stiffness of one segment, from B.9 (analytic) or B.13 (identified).
        n_segments: n_s.

    Returns:
        Array of n_s joint stiffnesses, joint 1 (the clamp) first.
    """
    stiffness = np.full(n_segments, 0.5 * k)
    stiffness[0] = k
    return stiffness


def joint_dampings(c: float, n_segments: int) -> np.ndarray:
    """Damping of every joint: ``c`` at the wall, ``c' = c / 2`` between segments (B.11)."""
    return joint_stiffnesses(c, n_segments)


def identified_segment_stiffness(k_total: float, n_segments: int) -> float:
    """Segment stiffness from the identified total, ``k_E = n_s k_tE`` (B.13)."""
    return n_segments * k_total


def identified_segment_damping(beta: float, c_total: float, n_segments: int) -> float:
    """Segment damping from the identified total, ``c_E = beta n_s c_tE`` (B.23)."""
    return beta * n_segments * c_total


def total_damping_from_ratio(damping_ratio: float, damped_omega: float) -> float:
    """The paper's total damping ``c_tE = 2 zeta omega_d`` (B.22).

    Args:
        damping_ratio: zeta.
        damped_omega: omega_d = 2 pi f_E, rad/s.

    Returns:
        c_tE as the paper defines it (units of 1/s: it is later scaled by beta).
    """
    return 2.0 * damping_ratio * damped_omega
