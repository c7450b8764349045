from dataclasses import replace

import numpy as np
import pytest

from lumpbeam_ros.model.chain import LumpedChain
from lumpbeam_ros.model.integrate import ChainState, ModalSolver, solve_reference
from lumpbeam_ros.model.parameters import BeamParameters, Effects
from lumpbeam_ros.model.statics import static_equilibrium


def _released(beam: BeamParameters) -> tuple[LumpedChain, ChainState]:
    """The drop test's start: at rest under 4.5 kg, then the load is gone."""
    loaded = LumpedChain.from_beam(beam, 4.5)
    state = ChainState(static_equilibrium(loaded), np.zeros(beam.n_segments))
    return LumpedChain.from_beam(beam, 0.0), state


@pytest.mark.parametrize('n', [3, 10])
def test_energy_is_conserved_without_damping(n):
    beam = BeamParameters(n_segments=n, beta_identified=0.0)
    chain, state = _released(beam)
    solution = ModalSolver(chain).solve(state, 3.0, 1 / 720)
    energy = chain.energy(solution.phi, solution.phi_dot)
    swing = chain.energy(state.phi, np.zeros(n)) - chain.energy(
        static_equilibrium(chain), np.zeros(n)
    )
    assert np.ptp(energy) < 1e-5 * swing


def test_energy_decays_with_damping():
    chain, state = _released(BeamParameters())
    solution = ModalSolver(chain).solve(state, 3.0, 1 / 180)
    energy = chain.energy(solution.phi, solution.phi_dot)
    assert np.all(np.diff(energy[::18]) < 0)


@pytest.mark.parametrize(
    ('effects', 'tolerance_m'),
    [
        (Effects(), 1e-7),
        (Effects(drag_c_q=0.5), 5e-6),
        (Effects(k_base_nm_per_rad=2e4, added_mass_kg=0.3), 1e-7),
        # Radau needs the friction sign smoothed; the modal solver steps it exactly.
        (Effects(coulomb_torque_nm=1.0), 1e-4),
    ],
)
def test_modal_solver_matches_radau(effects, tolerance_m):
    beam = replace(BeamParameters(), effects=effects)
    chain, state = _released(beam)
    solution = ModalSolver(chain).solve(state, 1.5, 1 / 180)
    reference = solve_reference(chain, state, solution.t, rtol=1e-9, atol=1e-11)
    z = chain.tip_pose(solution.phi)[1]
    z_ref = chain.tip_pose(reference.phi)[1]
    assert np.max(np.abs(z - z_ref)) < tolerance_m


def test_large_rotation_falls_back_or_converges():
    # A soft beam swinging through tens of degrees is far from its linearisation.
    soft = BeamParameters(n_segments=4, k_total_nm_per_rad=60.0, tip_mass_kg=0.5)
    chain = LumpedChain.from_beam(soft)
    state = ChainState(np.zeros(4), np.zeros(4))  # released straight, far from equilibrium
    solution = ModalSolver(chain).solve(state, 1.0, 1 / 180)
    reference = solve_reference(chain, state, np.linspace(0, 1.0, 181))
    if solution is not None:
        assert np.max(np.abs(solution.phi - reference.phi)) < 1e-5
    assert np.max(np.abs(reference.phi)) > 0.3
