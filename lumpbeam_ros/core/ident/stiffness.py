"""Stiffness from a static change (B.12) and from a frequency, with standard deviations."""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

from lumpbeam_ros.core.ident.mode_estimate import TWO_PI
from lumpbeam_ros.core.model import rules
from lumpbeam_ros.core.model.parameters import BeamParameters
from lumpbeam_ros.core.model.statics import static_tip_deflection

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
    deflection_m: float,
    deflection_std_m: float,
    load_kg: float,
    length_m: float,
    g: float,
    formula_share: float = 0.0,
) -> StaticStiffness:
    """k_tE by B.12 and the vertical stiffness from a static deflection.

    Args:
        deflection_m: delta_vE, the change of the static tip level (positive).
        deflection_std_m: Its standard deviation.
        load_kg: The released mass m_l (F = m_l g).
        length_m: Beam length L.
        g: Gravity.
        formula_share: B.12's own relative error on such a beam (:func:`formula_share`),
            added to k_tE's relative std: the formula, not only the noise, errs.

    Returns:
        The stiffnesses, NaN when the deflection is not positive; the relative std of the
        vertical one is that of the deflection (the load and length are taken as exact).
    """
    if not (deflection_m > 0.0 and load_kg > 0.0):
        return StaticStiffness()
    force = load_kg * g
    total = rules.total_stiffness_from_deflection(force, length_m, deflection_m)
    vertical = force / deflection_m
    relative = deflection_std_m / deflection_m
    total_std = total * math.hypot(relative, formula_share)
    return StaticStiffness(total, total_std, vertical, vertical * relative)


@functools.lru_cache(maxsize=64)
def formula_share(beam: BeamParameters, load_after_kg: float, load_kg: float) -> float:
    """How far B.12 is from the lumped beam it describes, relative (0: exactly).

    B.12 is the small-deflection rule of a uniform cantilever; the lumped chain under a real
    load sags along its own equilibrium (B.13). Applied to the chain's own static
    deflection, the rule does not give back the chain's k_tE: the paper beam's 4.5 kg
    release gives 3885.3 N m/rad for 3899.1, 0.36 % low, four hundred times the noise's
    standard deviation in the demo. That share belongs in k_tE's standard deviation.

    Args:
        beam: The configured beam (what the drop test measures).
        load_after_kg: The load left at the tip after the release.
        load_kg: The released load.

    Returns:
        ``|k_B12 / k_tE - 1|`` on the configured beam (0 when it cannot be computed).
    """
    if not (load_kg > 0.0 and math.isfinite(load_after_kg) and load_after_kg >= 0.0):
        return 0.0
    deflection = static_tip_deflection(beam, load_after_kg + load_kg) - static_tip_deflection(
        beam, load_after_kg
    )
    if not deflection > 0.0:
        return 0.0
    total = rules.total_stiffness_from_deflection(
        load_kg * beam.gravity_mps2, beam.length_m, deflection
    )
    return abs(total / beam.k_total_nm_per_rad - 1.0)


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
