"""The beam's EI and own mass fitted across a campaign, as the paper's Table B.1 method.

Each bag gives the static rise of the tip when its hanging load m_l leaves
(``static_deflection_m``, delta_vE) and the level it settles to with no load
(``level_after_m``). Across loads:

- EI from the end-load deflection (B.3), ``delta_vE = F L^3 / (3 EI)`` with ``F = m_l g``:
  a weighted least-squares line through the origin of delta_vE against F, slope
  ``s = L^3 / (3 EI)``, so ``EI = L^3 / (3 s)`` and ``k_tE = 2 EI / L`` (B.6, B.12);
- the beam's mass from the unloaded sag, the sum (B.5) of its own weight as a uniform load
  (B.1, ``q = m_b g / L``) and the mounted tip mass m_d as an end load (B.3):
  ``delta_0 = m_b g L^3 / (8 EI) + m_d g L^3 / (3 EI)``, so
  ``m_b = 8 EI delta_0 / (g L^3) - 8 m_d / 3``;
- a consistency check from the dynamics: after the release the beam oscillates unloaded at
  ``f = sqrt(k_v / m_eff) / (2 pi)`` with ``k_v = 3 EI / L^3`` (B.3) and Rayleigh's
  ``m_eff = m_d + 33/140 m_b``, whatever load hung before; that prediction from the static
  fit is set beside the measured frequencies.

Standard deviations come from the bags' own ``_std`` (weights) and are scaled by the
square root of the reduced chi-square when the bags scatter more than their stds say.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from lumpbeam_ros.core.ident.stiffness import RAYLEIGH_BEAM_FRACTION

#: The method in words, for a reader of the campaign's report (the module's docstring in full).
METHOD = (
    "EI comes from the tip's static rise when the hanging load leaves (B.3): a weighted "
    'straight line through the origin of the rise against the load, whose slope is '
    "L^3 / (3 EI); k_tE = 2 EI / L (B.6, B.12). The beam's own mass comes from the level "
    'the unloaded tip settles to, its weight a uniform load and the mounted mass an end load '
    '(B.1, B.3, B.5). As a check, the unloaded frequency predicted from EI and the mass '
    "(Rayleigh's effective mass) is set beside the measured one. Standard deviations come "
    "from the bags' own and grow when the bags scatter more than those say."
)


@dataclass(frozen=True)
class BeamFit:
    """The beam fitted across the campaign.

    Attributes:
        bending_stiffness_nm2: EI (B.3), N m^2.
        bending_stiffness_nm2_std: Its std.
        k_total_nm_per_rad: ``2 EI / L`` (B.6, B.12).
        k_total_nm_per_rad_std: Its std.
        beam_mass_kg: m_b from the unloaded sag (B.1, B.3, B.5).
        beam_mass_kg_std: Its std.
        unloaded_sag_m: delta_0, the weighted mean of ``-level_after_m``.
        unloaded_sag_m_std: Its std.
        static_chi2: Reduced chi-square of the deflection line (1: scatter as the stds say).
        frequency_predicted_hz: f of the unloaded beam from EI and m_b (Rayleigh).
        frequency_measured_hz: Weighted mean of the bags' ``natural_frequency_hz``.
        frequency_measured_hz_std: Its std.
        n_bags: Bags used.
    """

    bending_stiffness_nm2: float
    bending_stiffness_nm2_std: float
    k_total_nm_per_rad: float
    k_total_nm_per_rad_std: float
    beam_mass_kg: float
    beam_mass_kg_std: float
    unloaded_sag_m: float
    unloaded_sag_m_std: float
    static_chi2: float
    frequency_predicted_hz: float
    frequency_measured_hz: float
    frequency_measured_hz_std: float
    n_bags: int


def weighted_mean(values: np.ndarray, stds: np.ndarray) -> tuple[float, float, float]:
    """Inverse-variance mean, its std (scaled by the scatter when larger), reduced chi-square.

    Args:
        values: Measurements.
        stds: Their standard deviations (positive).

    Returns:
        ``(mean, std, reduced chi2)``; the chi-square is NaN for a single value.
    """
    w = 1.0 / np.asarray(stds, float) ** 2
    mean = float(np.sum(w * values) / np.sum(w))
    chi2 = (
        float(np.sum(w * (values - mean) ** 2) / (values.size - 1))
        if values.size > 1
        else math.nan
    )
    scale = math.sqrt(max(1.0, chi2)) if math.isfinite(chi2) else 1.0
    return mean, scale / math.sqrt(float(np.sum(w))), chi2


def slope_through_origin(
    x: np.ndarray, y: np.ndarray, y_std: np.ndarray
) -> tuple[float, float, float]:
    """Weighted least squares of ``y = s x``.

    Returns:
        ``(s, std of s, reduced chi2)``; the std is scaled by the scatter when larger.
    """
    w = 1.0 / np.asarray(y_std, float) ** 2
    sxx = float(np.sum(w * x * x))
    s = float(np.sum(w * x * y)) / sxx
    chi2 = float(np.sum(w * (y - s * x) ** 2) / (x.size - 1)) if x.size > 1 else math.nan
    scale = math.sqrt(max(1.0, chi2)) if math.isfinite(chi2) else 1.0
    return s, scale / math.sqrt(sxx), chi2


def fit_beam(
    load_kg: np.ndarray,
    deflection_m: np.ndarray,
    deflection_std_m: np.ndarray,
    level_after_m: np.ndarray,
    level_after_std_m: np.ndarray,
    frequency_hz: np.ndarray,
    frequency_std_hz: np.ndarray,
    length_m: float,
    gravity_mps2: float,
    tip_mass_kg: float,
) -> BeamFit:
    """EI, k_tE and m_b from the bags' static levels; the frequency they imply.

    Args:
        load_kg: m_l released in each bag.
        deflection_m: delta_vE of each bag (positive).
        deflection_std_m: Their stds.
        level_after_m: Tip z with no hanging load (negative: below the unbent beam).
        level_after_std_m: Their stds.
        frequency_hz: f_n of each bag.
        frequency_std_hz: Their stds.
        length_m: L.
        gravity_mps2: g.
        tip_mass_kg: m_d, the body mounted at the tip.

    Returns:
        The fit.

    Raises:
        ValueError: Fewer than two bags, or no load above zero.
    """
    load_kg = np.asarray(load_kg, float)
    if load_kg.size < 2 or not np.any(load_kg > 0.0):
        raise ValueError('the beam fit needs at least two bags with a released load')
    force = load_kg * gravity_mps2
    length3 = length_m**3
    s, s_std, chi2 = slope_through_origin(force, deflection_m, deflection_std_m)
    ei = length3 / (3.0 * s)
    ei_std = ei * s_std / s
    sag, sag_std, _ = weighted_mean(-np.asarray(level_after_m, float), level_after_std_m)
    # m_b = 8 EI sag / (g L^3) - 8 m_d / 3; EI and the sag come from different data.
    mass = 8.0 * ei * sag / (gravity_mps2 * length3) - 8.0 * tip_mass_kg / 3.0
    dmass_dei = 8.0 * sag / (gravity_mps2 * length3)
    dmass_dsag = 8.0 * ei / (gravity_mps2 * length3)
    mass_std = math.hypot(dmass_dei * ei_std, dmass_dsag * sag_std)
    f_mean, f_std, _ = weighted_mean(np.asarray(frequency_hz, float), frequency_std_hz)
    m_eff = tip_mass_kg + RAYLEIGH_BEAM_FRACTION * mass
    predicted = math.sqrt(3.0 * ei / length3 / m_eff) / (2.0 * math.pi) if m_eff > 0 else math.nan
    return BeamFit(
        bending_stiffness_nm2=ei,
        bending_stiffness_nm2_std=ei_std,
        k_total_nm_per_rad=2.0 * ei / length_m,
        k_total_nm_per_rad_std=2.0 * ei_std / length_m,
        beam_mass_kg=mass,
        beam_mass_kg_std=mass_std,
        unloaded_sag_m=sag,
        unloaded_sag_m_std=sag_std,
        static_chi2=chi2,
        frequency_predicted_hz=predicted,
        frequency_measured_hz=f_mean,
        frequency_measured_hz_std=f_std,
        n_bags=int(load_kg.size),
    )
