"""A beam updated with identified stiffness and damping (what the simulator adopts live).

The identifier reports the total stiffness k_tE (B.12) and the first mode's damping ratio.
k_tE goes into the beam as it is (B.13 spreads it over the joints). The damping is not taken
as B.22's c_tE: B.22 treats the tip as a single oscillator, while the chain spreads
``c_E = beta n_s c_tE`` (B.23) over every joint, so c_tE from B.22 does not give the chain the
measured damping ratio (the paper tunes beta for that). Instead c_tE is scaled until the
chain's first mode, unloaded, has the identified ratio: for the light damping of a beam the
ratio is proportional to c_tE, so two proportional corrections land within 1e-6.
"""

from __future__ import annotations

import math
from dataclasses import replace

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model import rules
from lumpbeam_ros.core.model.chain import LumpedChain
from lumpbeam_ros.core.model.modes import chain_modes
from lumpbeam_ros.core.model.parameters import BeamParameters

#: Proportional corrections of c_tE (see the module docstring).
_DAMPING_ITERATIONS = 3
#: How far an identified stiffness may lie from the model's own, either way: a factor the
#: fits never reach on a real structure, and that keeps a mis-scaled or fabricated value
#: (1, 1e-300 or 8.6e302 N m/rad on a 3899 N m/rad beam) away from the solvers.
MAX_STIFFNESS_FACTOR = 10.0


def first_mode(beam: BeamParameters, load_kg: float = 0.0) -> tuple[float, float, float]:
    """The beam's first mode about its equilibrium under ``load_kg``.

    Returns:
        ``(natural frequency Hz, damped frequency Hz, damping ratio)``.

    Raises:
        LumpbeamError: The chain has no oscillating mode (overdamped).
    """
    modes = chain_modes(LumpedChain.from_beam(beam, load_kg))
    if modes.natural_frequency_hz.size == 0:
        raise LumpbeamError('the beam has no oscillating mode (overdamped)')
    return (
        float(modes.natural_frequency_hz[0]),
        float(modes.damped_frequency_hz[0]),
        float(modes.damping_ratio[0]),
    )


def adopt_identified(
    beam: BeamParameters, stiffness_total_nm_per_rad: float, damping_ratio: float
) -> BeamParameters:
    """Returns ``beam`` with an identified k_tE and the c_tE that gives it ``damping_ratio``.

    The beam switches to the identified rules (B.13, B.23) with its own ``beta_identified``.

    Args:
        beam: The beam so far.
        stiffness_total_nm_per_rad: k_tE (B.12), N m/rad.
        damping_ratio: The first mode's identified damping ratio (0 <= zeta < 1).

    Returns:
        The updated beam; its unloaded first mode has ``damping_ratio``.

    Raises:
        LumpbeamError: A non-positive or non-finite stiffness, one more than
            :data:`MAX_STIFFNESS_FACTOR` times the beam's either way, a ratio outside
            [0, 1), or a beam whose ``beta_identified`` is 0 while damping is asked for.
    """
    k_total, zeta = float(stiffness_total_nm_per_rad), float(damping_ratio)
    if not math.isfinite(k_total) or k_total <= 0.0:
        raise LumpbeamError(f'identified stiffness must be positive, got {k_total!r} N m/rad')
    own = beam.segment_stiffness() / beam.n_segments  # the beam's k_tE (B.13)
    if not own / MAX_STIFFNESS_FACTOR <= k_total <= own * MAX_STIFFNESS_FACTOR:
        raise LumpbeamError(
            f'identified stiffness {k_total:.6g} N m/rad is not within a factor of '
            f"{MAX_STIFFNESS_FACTOR:g} of the beam's {own:.6g} N m/rad"
        )
    if not math.isfinite(zeta) or not 0.0 <= zeta < 1.0:
        raise LumpbeamError(f'identified damping ratio must be in [0, 1), got {zeta!r}')
    adopted = replace(beam, stiffness_source='identified', k_total_nm_per_rad=k_total)
    if zeta == 0.0:
        return replace(adopted, c_total=0.0)
    if adopted.beta_identified <= 0.0:
        raise LumpbeamError('beta_identified is 0: no c_tE can give the identified damping')
    if adopted.c_total <= 0.0:
        _, f_d, _ = first_mode(replace(adopted, c_total=0.0))
        # B.22 as the paper uses it: a start of the right order for the scaling below.
        adopted = replace(
            adopted, c_total=rules.total_damping_from_ratio(zeta, 2.0 * math.pi * f_d)
        )
    for _ in range(_DAMPING_ITERATIONS):
        _, _, zeta_model = first_mode(adopted)
        adopted = replace(adopted, c_total=adopted.c_total * zeta / zeta_model)
    return adopted
