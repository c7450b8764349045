"""Stiffness from a static change (B.12) and from a frequency, with standard deviations."""

from __future__ import annotations

import math
from dataclasses import dataclass

from lumpbeam_ros.core.ident.mode_estimate import TWO_PI
from lumpbeam_ros.core.model import rules

NAN = float('nan')

#: Rayleigh's share of a cantilever's own mass that moves with its tip in the first mode.
RAYLEIGH_BEAM_FRACTION = 33.0 / 140.0


@dataclass(frozen=True)
class StaticStiffness:
    """Stiffness from the static rise of the tip when a known load leaves.

    Attributes:
        total_nm_per_rad: k_tE = 2 F L^2 / (3 delta_vE) (B.12).
        vertical_n_per_m: F / delta_vE.
    """

    total_nm_per_rad: float = NAN
    total_nm_per_rad_std: float = NAN
    vertical_n_per_m: float = NAN
    vertical_n_per_m_std: float = NAN


def from_static_change(
    deflection_m: float, deflection_std_m: float, load_kg: float, length_m: float, g: float
) -> StaticStiffness:
    """k_tE by B.12 and the vertical stiffness from a static deflection.

    Args:
        deflection_m: delta_vE, the change of the static tip level (positive).
        deflection_std_m: Its standard deviation.
        load_kg: The released mass m_l (F = m_l g).
        length_m: Beam length L.
        g: Gravity.

    Returns:
        The stiffnesses, NaN when the deflection is not positive; the relative std of both
        is that of the deflection (the load and length are taken as exact).
    """
    if not (deflection_m > 0.0 and load_kg > 0.0):
        return StaticStiffness()
    force = load_kg * g
    total = rules.total_stiffness_from_deflection(force, length_m, deflection_m)
    vertical = force / deflection_m
    relative = deflection_std_m / deflection_m
    return StaticStiffness(total, total * relative, vertical, vertical * relative)


def from_pitch_change(
    pitch_change_rad: float, pitch_change_std_rad: float, load_kg: float, length_m: float, g: float
) -> tuple[float, float]:
    """k_tE by the slope form of B.12, ``k_tE = F L / delta_thetaE``, with its std.

    Args:
        pitch_change_rad: The fall of the static tip pitch when the load leaves (positive).
        pitch_change_std_rad: Its standard deviation.
        load_kg: The released mass.
        length_m: Beam length L.
        g: Gravity.

    Returns:
        k_tE and its std (NaN when the change is not positive).
    """
    if not (pitch_change_rad > 0.0 and load_kg > 0.0):
        return NAN, NAN
    total = load_kg * g * length_m / pitch_change_rad
    return total, total * pitch_change_std_rad / pitch_change_rad


def from_frequency(
    natural_frequency_hz: float,
    natural_frequency_std_hz: float,
    tip_mass_kg: float,
    beam_mass_kg: float,
    beam_fraction: float = RAYLEIGH_BEAM_FRACTION,
) -> tuple[float, float]:
    """Vertical stiffness implied by a natural frequency and a one-mass model.

    ``k = m_eff (2 pi f_n)^2`` with ``m_eff = m_tip + fraction * m_beam`` (Rayleigh's
    cantilever with a tip mass). A cross-check only: the effective mass is approximate, and
    its error (a few per cent) is not in the returned std.

    Args:
        natural_frequency_hz: f_n of the first mode.
        natural_frequency_std_hz: Its std.
        tip_mass_kg: Mass at the tip after the release (m_d plus any load left).
        beam_mass_kg: m_b.
        beam_fraction: Share of m_b that moves with the tip.

    Returns:
        The stiffness, N/m, and its std.
    """
    mass = tip_mass_kg + beam_fraction * beam_mass_kg
    omega = TWO_PI * natural_frequency_hz
    stiffness = mass * omega * omega
    if not math.isfinite(stiffness):
        return NAN, NAN
    return stiffness, 2.0 * stiffness * natural_frequency_std_hz / natural_frequency_hz
