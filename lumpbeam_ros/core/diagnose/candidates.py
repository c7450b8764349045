"""The models a diagnosis compares: the nominal beam and one candidate per missing effect.

Every model refits the two nominal parameters that the data identify and that trade off with
the effects: ``k_total_nm_per_rad`` (k_tE, B.12: the static drop and the frequency) and
``beta_identified`` (B.23: the damping), as logarithms of their ratio to the starting values
(positive by construction, order one whatever the unit).

A candidate adds one *strength*: a quantity that is zero when the effect is off and grows
with it, fitted linearly in units of ``scale``. For most effects it is the contract parameter
itself; for ``base_compliance`` it is the mount's compliance relative to the clamp joint,
``k_clamp / k_base`` (a rigid mount is 0, where ``k_base`` would be infinite), for
``sensor_scale`` the scale's departure from 1. So the nominal model is the candidate at
strength 0, a bound that the least squares reaches in a step or two when the data hold no
such effect, instead of crawling along a log-parameter to -inf. Three effects have a sign
(``cubic_stiffness`` hardens or softens, ``sensor_scale`` is above or below 1,
``mount_tilt`` is down or up): their strength is searched on both sides of 0.

Each strength has a search bound, beyond its plausible range: a best fit outside the
plausible range (or pinned at the bound) is unphysical, and a diagnosis that needs it is
``unexplained``, not a name.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from lumpbeam_ros.core.model.chain import LumpedChain
from lumpbeam_ros.core.model.parameters import EFFECTS, BeamParameters, Effects
from lumpbeam_ros.core.model.statics import static_equilibrium

NOMINAL = 'nominal'

#: Refit range of the nominal parameters, as factors of their starting values.
STIFFNESS_FACTORS = (0.2, 5.0)
DAMPING_FACTORS = (1e-3, 1e3)


@dataclass(frozen=True)
class Candidate:
    """One model: the nominal beam, or the nominal beam plus one effect.

    Attributes:
        name: ``'nominal'`` or an effect name of doc/interfaces.md, 'Missing effects'.
        parameter: The effect's contract parameter name (``None`` for the nominal model).
        scale: Unit of the fitted strength (``x[2] = strength / scale``).
        search_max: Largest strength searched.
        plausible_max: Largest strength a real setup can have.
        start: Strength a fit starts from: small, but felt by the data.
        reciprocal: The contract parameter is ``reference / strength`` (a compliance fitted
            for a stiffness), else the strength itself.
        reference: See ``reciprocal``.
        signed: The strength may be negative (searched down to ``-search_max``).
        offset: The contract parameter's "off" value, added to a non-reciprocal strength
            (``sensor_scale``: 1).
    """

    name: str
    parameter: str | None = None
    scale: float = 1.0
    search_max: float = math.inf
    plausible_max: float = math.inf
    start: float = 0.0
    reciprocal: bool = False
    reference: float = 1.0
    signed: bool = False
    offset: float = 0.0

    @property
    def n_parameters(self) -> int:
        """Fitted parameters: k_tE and beta, plus the effect's one."""
        return 2 if self.parameter is None else 3

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Bounds of ``x = [ln k/k0, ln beta/beta0, strength/scale]``."""
        lo = [math.log(STIFFNESS_FACTORS[0]), math.log(DAMPING_FACTORS[0])]
        hi = [math.log(STIFFNESS_FACTORS[1]), math.log(DAMPING_FACTORS[1])]
        if self.parameter is not None:
            lo.append(-self.search_max / self.scale if self.signed else 0.0)
            hi.append(self.search_max / self.scale)
        return np.asarray(lo), np.asarray(hi)

    def step_floor(self) -> np.ndarray:
        """Magnitudes of ``x`` below which a fit's finite-difference step stops shrinking.

        The effect's starting strength (small, but felt by the data); none for the
        log-parameters, whose steps the data feel even at 0
        (:func:`~lumpbeam_ros.core.diagnose.fitting.forward_jacobian`).
        """
        if self.parameter is None:
            return np.zeros(2)
        return np.array([0.0, 0.0, abs(self.start / self.scale)])

    def start_x(self, nominal_x: np.ndarray, strength: float | None = None) -> np.ndarray:
        """Starting point: the nominal model's refit values and a strength.

        Args:
            nominal_x: The nominal fit's ``[ln k/k0, ln beta/beta0]``.
            strength: The starting strength (default: :attr:`start`).

        Returns:
            The starting ``x``.
        """
        if self.parameter is None:
            return np.asarray(nominal_x[:2], dtype=float)
        return np.asarray(
            np.r_[nominal_x[:2], (self.start if strength is None else strength) / self.scale]
        )

    def value(self, x: np.ndarray) -> float:
        """The effect's contract parameter (SI) at ``x``; NaN for the nominal model.

        A reciprocal parameter at strength 0 is infinite (a rigid mount).
        """
        if self.parameter is None:
            return float('nan')
        return self.parameter_value(float(x[2]))

    def parameter_value(self, x_strength: float) -> float:
        """The contract parameter (SI) at a fitted strength ``x_strength`` (units of scale)."""
        strength = x_strength * self.scale
        if not self.reciprocal:
            return self.offset + strength
        return self.reference / strength if strength > 0.0 else math.inf

    def strength_physical(self, x_strength: float) -> bool:
        """Whether a fitted strength lies inside the plausible range, off the search bound."""
        strength = abs(x_strength) * self.scale
        return strength <= min(self.plausible_max, (1.0 - 1e-3) * self.search_max)

    def beam(self, nominal: BeamParameters, x: np.ndarray) -> BeamParameters:
        """The beam that ``x`` describes.

        Args:
            nominal: The nominal beam in identified form (the reference of ``x``); any
                effects it has stay on.
            x: ``[ln k/k0, ln beta/beta0]`` and, for an effect, its strength.

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
        value = self.value(x)
        # Effects take 0 for "off"; an infinitely stiff mount is off.
        value = 0.0 if math.isinf(value) else value
        return replace(beam, effects=beam.effects.with_effect(self.name, value))

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

    def physical(self, x: np.ndarray) -> bool:
        """Whether the fit stays off its bounds and inside the plausible strength."""
        lo, hi = self.bounds()
        margin = 1e-3 * (hi[:2] - lo[:2])
        if np.any(x[:2] <= lo[:2] + margin) or np.any(x[:2] >= hi[:2] - margin):
            return False
        return self.parameter is None or self.strength_physical(float(x[2]))


def nominal_candidate() -> Candidate:
    """The nominal model: k_tE and beta refit, no effect."""
    return Candidate(NOMINAL)


#: The effects the diagnosis fits, by their contract names: every effect of the model.
SEARCHED_EFFECTS = tuple(EFFECTS)


def effect_candidates(nominal: BeamParameters) -> list[Candidate]:
    """The effects the diagnosis searches, with ranges scaled to the beam.

    Every effect of :data:`SEARCHED_EFFECTS`, each searched as its record says
    (:class:`~lumpbeam_ros.core.model.parameters.SearchRange`).

    Args:
        nominal: The nominal beam; its clamp stiffness, masses and length set the scales.

    Returns:
        One candidate per searched effect, in the order of doc/interfaces.md, 'Missing
        effects'.
    """
    k_clamp = float(nominal.joint_stiffness()[0])
    carried_kg = nominal.tip_mass_kg + nominal.mass_kg
    # A hardening of 1 % of the clamp's tangent stiffness at its unloaded rest angle.
    rest = static_equilibrium(LumpedChain.from_beam(replace(nominal, effects=Effects())))
    references = {
        '': 1.0,
        'clamp_moment': nominal.gravity_mps2 * carried_kg * nominal.length_m,
        'carried_kg': carried_kg,
        'k3_unit': 0.01 * k_clamp / (3.0 * max(float(rest[0]) ** 2, 1e-12)),
    }
    candidates = []
    for name in SEARCHED_EFFECTS:
        record = EFFECTS[name]
        r = record.search
        scale, search_max, plausible, start = (
            value * references[per]
            for value, per in zip(
                (r.scale, r.search_max, r.plausible_max, r.start), r.per, strict=True
            )
        )
        candidates.append(
            Candidate(
                name,
                record.parameter,
                scale,
                search_max,
                plausible,
                start,
                reciprocal=record.compliance,
                reference=k_clamp,
                signed=record.signed,
                offset=record.off,
            )
        )
    return candidates
