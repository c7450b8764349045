"""The models a diagnosis compares: the nominal beam and one candidate per SPEC section 6 effect.

Every model refits the two nominal parameters that the data identify and that trade off with
the effects: ``k_total_nm_per_rad`` (k_tE, B.12: the static drop and the frequency) and
``beta_identified`` (B.23: the damping). A candidate adds its effect's one parameter. All
parameters are fitted as logarithms relative to a scale, so the least squares sees numbers
of order one whatever the unit, and positivity holds by construction.

Each effect has a search range, wider than its plausible range: a best fit outside the
plausible range (or pinned to the search bound) is unphysical, and a diagnosis that needs it
is ``unexplained``, not a name.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from lumpbeam_ros.model.parameters import EFFECT_PARAMETERS, BeamParameters

NOMINAL = 'nominal'

#: Refit range of the nominal parameters, as factors of their starting values.
STIFFNESS_FACTORS = (0.2, 5.0)
DAMPING_FACTORS = (1e-3, 1e3)


@dataclass(frozen=True)
class Candidate:
    """One model: the nominal beam, or the nominal beam plus one effect.

    Attributes:
        name: ``'nominal'`` or an effect name of SPEC section 6.
        parameter: The effect's SPEC parameter name (``None`` for the nominal model).
        scale: The unit the effect is fitted in (its log is fitted relative to it).
        search: Bounds of the fitted value.
        plausible: Values a real setup can have; outside them a fit is unphysical.
        start: Where a fit starts: a small effect, a perturbation the data feel but far
            from the nominal model's nesting limit, where the log-gradient would vanish.
    """

    name: str
    parameter: str | None = None
    scale: float = 1.0
    search: tuple[float, float] = (0.0, 0.0)
    plausible: tuple[float, float] = (0.0, math.inf)
    start: float = 1.0

    @property
    def n_parameters(self) -> int:
        """Fitted parameters: k_tE and beta, plus the effect's one."""
        return 2 if self.parameter is None else 3

    def bounds(self, nominal: BeamParameters) -> tuple[np.ndarray, np.ndarray]:
        """Bounds of the fitted log-parameters ``[ln k/k0, ln beta/beta0, ln p/scale]``."""
        lo = [math.log(STIFFNESS_FACTORS[0]), math.log(DAMPING_FACTORS[0])]
        hi = [math.log(STIFFNESS_FACTORS[1]), math.log(DAMPING_FACTORS[1])]
        if self.parameter is not None:
            lo.append(math.log(self.search[0] / self.scale))
            hi.append(math.log(self.search[1] / self.scale))
        return np.asarray(lo), np.asarray(hi)

    def beam(self, nominal: BeamParameters, x: np.ndarray) -> BeamParameters:
        """The beam that the log-parameters ``x`` describe.

        Args:
            nominal: The nominal beam (identified form, no effects): the reference of ``x``.
            x: ``[ln k/k0, ln beta/beta0]`` and, for an effect, ``ln p/scale``.

        Returns:
            The beam with the refit nominal parameters and the effect switched on.
        """
        beam = replace(
            nominal,
            k_total_nm_per_rad=nominal.k_total_nm_per_rad * math.exp(x[0]),
            beta_identified=nominal.beta_identified * math.exp(x[1]),
        )
        if self.parameter is None:
            return beam
        return replace(beam, effects=beam.effects.with_effect(self.name, self.value(x)))

    def start_x(self, nominal_x: np.ndarray) -> np.ndarray:
        """Starting log-parameters: the nominal model's refit values and the small start."""
        if self.parameter is None:
            return np.asarray(nominal_x[:2], dtype=float)
        return np.r_[nominal_x[:2], math.log(self.start / self.scale)]

    def value(self, x: np.ndarray) -> float:
        """The effect's parameter in SI units (NaN for the nominal model)."""
        return float('nan') if self.parameter is None else self.scale * math.exp(x[2])

    def values(self, nominal: BeamParameters, x: np.ndarray) -> dict[str, float]:
        """All fitted parameters by name: the refit nominal ones and the effect's."""
        beam = self.beam(nominal, x)
        out = {
            'k_total_nm_per_rad': beam.k_total_nm_per_rad,
            'beta_identified': beam.beta_identified,
        }
        if self.parameter is not None:
            out[self.parameter] = self.value(x)
        return out

    def physical(self, nominal: BeamParameters, x: np.ndarray) -> bool:
        """Whether the fitted values are within their search bounds and plausible range."""
        lo, hi = self.bounds(nominal)
        margin = 1e-3 * (hi - lo)
        if np.any(x[:2] <= lo[:2] + margin[:2]) or np.any(x[:2] >= hi[:2] - margin[:2]):
            return False
        if self.parameter is None:
            return True
        # Pinned at the upper search bound, the effect wanted to be larger still.
        if x[2] >= hi[2] - margin[2]:
            return False
        value = self.value(x)
        return self.plausible[0] <= value <= self.plausible[1]


def nominal_candidate() -> Candidate:
    """The nominal model: k_tE and beta refit, no effect."""
    return Candidate(NOMINAL)


def effect_candidates(nominal: BeamParameters) -> list[Candidate]:
    """The five effects of SPEC section 6, with ranges scaled to the beam.

    Args:
        nominal: The nominal beam; its clamp stiffness, masses and length set the scales.

    Returns:
        One candidate per effect, in the order of SPEC section 6.
    """
    k_clamp = float(nominal.joint_stiffness()[0])
    carried_kg = nominal.tip_mass_kg + nominal.mass_kg
    clamp_moment = nominal.gravity_mps2 * carried_kg * nominal.length_m
    table = {
        # A mount much softer than the beam's own root would not be "a beam on a mount".
        'base_compliance': (
            k_clamp,
            (1e-3 * k_clamp, 1e4 * k_clamp),
            (0.05 * k_clamp, math.inf),
            10.0 * k_clamp,
        ),
        # Dry friction beyond a tenth of the clamp's static moment would lock the beam.
        'coulomb_friction': (
            1.0,
            (1e-5 * clamp_moment, clamp_moment),
            (0.0, 0.1 * clamp_moment),
            0.1,
        ),
        # c_q = rho C_d A / 2: 20 N s^2/m^2 is a plate of ~30 m^2; a tip body is far less.
        'quadratic_drag': (1.0, (1e-4, 1e3), (0.0, 20.0), 0.05),
        # More than twice what the beam already carries is not an unnoticed bracket.
        'added_mass': (1.0, (1e-4, 20.0 * carried_kg), (0.0, 2.0 * carried_kg), 0.03),
        # Beyond a quarter of a second a camera pipeline is broken, not late.
        'sensor_latency': (0.01, (1e-5, 2.0), (0.0, 0.25), 0.002),
    }
    return [
        Candidate(name, EFFECT_PARAMETERS[name], scale, search, plausible, start)
        for name, (scale, search, plausible, start) in table.items()
    ]
