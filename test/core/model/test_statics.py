import math
from dataclasses import replace

import numpy as np
import pytest

from lumpbeam_ros.core.model import rules
from lumpbeam_ros.core.model.chain import LumpedChain
from lumpbeam_ros.core.model.parameters import BeamParameters, Effects, load_beam_config
from lumpbeam_ros.core.model.statics import carries, static_equilibrium, static_tip_deflection

# A stiff beam keeps rotations tiny, so the comparison is with linear Euler-Bernoulli theory.
STIFF = BeamParameters(stiffness_source='analytic', bending_stiffness_nm2=5e6, tip_mass_kg=0.0)


def _errors(load_kg: float, analytic: float) -> list[float]:
    errors = []
    for n in (2, 5, 20, 80):
        beam = replace(STIFF, n_segments=n)
        if load_kg:
            value = static_tip_deflection(beam, load_kg) - static_tip_deflection(beam)
        else:
            value = static_tip_deflection(beam)
        errors.append(abs(value / analytic - 1.0))
    return errors


def test_end_load_converges_to_b3():
    force = 4.5 * STIFF.gravity_mps2
    errors = _errors(4.5, rules.end_load_deflection(force, STIFF.length_m, 5e6))
    assert all(np.diff(errors) < 0)
    assert errors[-1] < 0.005


def test_uniform_load_converges_to_b1():
    q = STIFF.mass_kg * STIFF.gravity_mps2 / STIFF.length_m
    errors = _errors(0.0, rules.uniform_load_deflection(q, STIFF.length_m, 5e6))
    assert all(np.diff(errors) < 0)
    assert errors[-1] < 0.01


@pytest.mark.parametrize('n', [1, 3, 10, 40])
def test_equilibrium_balances_b16(n):
    chain = LumpedChain.from_beam(BeamParameters(n_segments=n), load_kg=4.5)
    phi = static_equilibrium(chain)
    residual = chain.generalized_forces(phi, np.zeros(n))
    assert np.max(np.abs(residual)) < 1e-8
    assert np.all(phi > 0)  # the beam sags downward everywhere


def test_a_beam_too_soft_for_its_load_is_reported():
    soft = BeamParameters(n_segments=3, k_total_nm_per_rad=1e-3)
    with pytest.raises(RuntimeError, match='cannot carry'):
        static_tip_deflection(soft, 100.0)


@pytest.mark.parametrize('tilt', [-0.4, 0.3, 1.0])
def test_a_tilted_clamp_deflects_as_a_cantilever_under_g_cos_tilt(tilt):
    # The deflection across the beam (in beam_base) comes from the transverse part of
    # gravity, g cos(tilt): B.1 for the beam's weight plus B.3 for the load. The axial part
    # stretches or compresses an inextensible beam, which only adds a P-delta term of order
    # (deflection / L) times the axial share: far below the tolerance for this stiff beam.
    beam = replace(STIFF, n_segments=80, effects=Effects(tilt_rad=tilt))
    g = STIFF.gravity_mps2 * np.cos(tilt)
    expected = rules.uniform_load_deflection(
        STIFF.mass_kg * g / STIFF.length_m, STIFF.length_m, 5e6
    ) + rules.end_load_deflection(4.5 * g, STIFF.length_m, 5e6)
    assert static_tip_deflection(beam, 4.5) == pytest.approx(expected, rel=0.01)


@pytest.mark.parametrize(
    ('kg', 'carried'),
    [(0.0, True), (4.5, True), (20.0, True), (30.0, False), (1000.0, False), (1e4, False),
     (1e300, False), (-1.0, False), (math.nan, False), (math.inf, False)],
)  # fmt: skip
def test_a_load_is_carried_when_it_sags_the_beam_a_tenth_of_its_length_at_most(kg, carried):
    # 20 kg sags the paper's beam 0.21 m, 30 kg 0.29 m: 9 % and 13 % of its 2.31 m.
    assert carries(load_beam_config()[0], kg) is carried
