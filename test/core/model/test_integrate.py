import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.signal import lfilter

from lumpbeam_ros.core.model.chain import LumpedChain
from lumpbeam_ros.core.model.integrate import (
    ChainState,
    ModalSolver,
    _free_response,
    first_order_scan,
    friction_steps,
    friction_steps_loop,
    solve_reference,
)
from lumpbeam_ros.core.model.parameters import BeamParameters, Effects
from lumpbeam_ros.core.model.statics import static_equilibrium


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
        # Dry friction: Radau needs the sign smoothed and a tight step (about 20 s).
        pytest.param(Effects(coulomb_torque_nm=1.0), 1e-4, marks=pytest.mark.slow),
        (Effects(k3_nm_per_rad3=1e8), 1e-6),
        (Effects(k3_nm_per_rad3=-5e7), 1e-6),
        (Effects(tilt_rad=0.2), 1e-7),
        pytest.param(
            Effects(k3_nm_per_rad3=1e8, coulomb_torque_nm=1.0), 1e-4, marks=pytest.mark.slow
        ),
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


def _duffing_period(omega0: float, epsilon: float, amplitude: float) -> float:
    """Exact period of ``x'' + omega0^2 x + epsilon x^3 = 0`` released at rest from ``A``.

    ``T = 4 int_0^A dx / sqrt(2 (V(A) - V(x)))`` with ``x = A sin(u)`` removing the
    endpoint singularity; numerical quadrature, independent of the chain and its solver.
    """

    def integrand(u: float) -> float:
        x = amplitude * np.sin(u)
        drop = omega0**2 * (amplitude**2 - x**2) / 2 + epsilon * (amplitude**4 - x**4) / 4
        return amplitude * np.cos(u) / np.sqrt(2.0 * drop)

    return 4.0 * quad(integrand, 0.0, np.pi / 2, epsabs=1e-14, epsrel=1e-12)[0]


@pytest.mark.slow
@pytest.mark.parametrize('k3', [4e4, -3e4])
def test_cubic_stiffness_shifts_the_frequency_as_duffing_predicts(k3):
    # One rigid segment without gravity or damping: J theta'' + k theta + k3 theta^3 = 0,
    # the undamped Duffing oscillator. Its period at 0.1 rad, hardening (shorter) or
    # softening (longer), against the exact quadrature; harmonic balance, omega^2 =
    # omega0^2 + 3 k3 A^2 / (4 J), agrees to first order in k3.
    beam = BeamParameters(
        n_segments=1, gravity_mps2=0.0, beta_identified=0.0, tip_mass_kg=2.5, mass_kg=1.9
    )
    beam = replace(beam, effects=Effects(k3_nm_per_rad3=k3))
    chain = LumpedChain.from_beam(beam)
    inertia = float(chain.mass_matrix(np.zeros(1))[0, 0])
    k = float(chain.stiffness[0])
    amplitude = 0.1
    start = ChainState(np.array([amplitude]), np.zeros(1))
    with np.errstate(all='ignore'):  # a diverging relaxation is detected and returns None
        solution = ModalSolver(chain).solve(start, 4.0, 1e-3)
    if solution is None:  # too nonlinear for the waveform relaxation: the simulator's fallback
        grid = np.linspace(0.0, 4.0, 4001)
        solution = solve_reference(chain, start, grid, rtol=1e-11, atol=1e-13)
    theta = solution.phi[:, 0]
    # Downward zero crossings, linearly interpolated: the period between the first and last.
    down = np.flatnonzero((theta[:-1] > 0) & (theta[1:] <= 0))
    crossings = solution.t[down] + theta[down] / (theta[down] - theta[down + 1]) * 1e-3
    period = (crossings[-1] - crossings[0]) / (crossings.size - 1)
    omega0 = np.sqrt(k / inertia)
    exact = _duffing_period(omega0, k3 / inertia, amplitude)
    linear = 2 * np.pi / omega0
    balance = 2 * np.pi / np.sqrt(omega0**2 + 0.75 * k3 / inertia * amplitude**2)
    assert abs(exact / linear - 1.0) > 0.01  # the shift is large enough to test
    assert period == pytest.approx(exact, rel=2e-5)
    assert abs(period / balance - 1.0) < 0.1 * abs(exact / linear - 1.0)


@pytest.mark.parametrize('torque', [0.0, 1.0])
def test_sweeps_stopped_on_the_predicted_change_are_within_the_tolerance(torque):
    beam = replace(BeamParameters(), effects=Effects().with_effect('coulomb_friction', torque))
    chain, state = _released(beam)
    solver = ModalSolver(chain)
    tol = 1e-11
    solution = solver.solve(state, 6.0, 1 / 180, tol=tol)
    strict = solver.solve(state, 6.0, 1 / 180, tol=1e-15)
    assert solution is not None and strict is not None
    # The stop is a sweep early (the change the next sweep would make predicted from the
    # contraction), yet as close to the fixed point as the tolerance says.
    assert 0.0 < np.max(np.abs(solution.phi - strict.phi)) < tol


@pytest.mark.parametrize('torque', [0.3, 1.0, 3.0])
def test_sliding_stretches_in_one_go_match_the_step_by_step_friction(torque):
    beam = replace(BeamParameters(), effects=Effects().with_effect('coulomb_friction', torque))
    chain, state = _released(beam)
    solver = ModalSolver(chain)
    h = 1 / 720
    e, gamma, angle_row = solver.friction_recurrence(h)
    drive = np.zeros((4321, e.size), dtype=complex)  # 6 s of free decay
    drive[0] = solver.modal_state(state)
    fast = friction_steps(drive, e, gamma, angle_row, torque)
    loop = friction_steps_loop(drive, e, gamma, angle_row, torque)
    angles = (loop @ angle_row).real
    # The decay slides back and forth and sticks for a few steps at the turns: both branches.
    stuck = np.abs(np.diff(angles)) < 1e-15
    assert np.ptp(angles) > 1e-3 and 0 < np.count_nonzero(stuck) < 0.5 * stuck.size
    np.testing.assert_allclose((fast @ angle_row).real, angles, rtol=0, atol=1e-14)
    np.testing.assert_allclose(fast, loop, rtol=0, atol=1e-12 * np.max(np.abs(loop)))


@pytest.mark.parametrize('count', [2, 3, 40])
def test_a_grid_ending_on_a_sliding_step_matches_the_step_by_step_friction(count):
    beam = replace(BeamParameters(), effects=Effects().with_effect('coulomb_friction', 0.3))
    chain, state = _released(beam)
    solver = ModalSolver(chain)
    e, gamma, angle_row = solver.friction_recurrence(1 / 720)
    moving = ChainState(state.phi, np.full(beam.n_segments, 0.5))  # sliding from the start
    drive = np.zeros((count, e.size), dtype=complex)
    drive[0] = solver.modal_state(moving)
    loop = friction_steps_loop(drive, e, gamma, angle_row, 0.3)
    fast = friction_steps(drive, e, gamma, angle_row, 0.3)
    np.testing.assert_allclose(fast, loop, rtol=0, atol=1e-12 * np.max(np.abs(loop)))


#: An unstable beam (a strongly softening spring, k3 = -1e10 N m/rad^3, outside the
#: parameter ranges): the modal solver gives up and Radau's steps shrink without end.
RUNAWAY = """
import numpy as np
from lumpbeam_ros.base.errors import SolverBudgetError
from lumpbeam_ros.core.model.chain import LumpedChain
from lumpbeam_ros.core.model.integrate import ChainState, solve_reference
from lumpbeam_ros.core.model.parameters import load_beam_config
from lumpbeam_ros.core.model.statics import static_equilibrium
from lumpbeam_ros.core.synthetic.drop_test import with_effects

nominal = load_beam_config()[0]
beam = with_effects(nominal, {'cubic_stiffness': K3})
phi = static_equilibrium(LumpedChain.from_beam(nominal, 4.5))
chain = LumpedChain.from_beam(beam, 0.0)
try:
    solve_reference(chain, ChainState(phi, 0 * phi), np.linspace(0, 2, 361))
except SolverBudgetError as exc:
    print('refused:', exc)
"""


@pytest.mark.parametrize('k3', [-1e10, -1e12])
def test_the_reference_integrator_stops_at_its_budget(k3):
    code = RUNAWAY.replace('K3', repr(k3))
    # In a process of its own: without a budget it would run for hours.
    run = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert run.stdout.startswith('refused: the reference integrator spent ')
    assert 'too stiff or unstable to simulate' in run.stdout
    assert run.stderr == ''  # no numpy warnings on the way


@pytest.mark.parametrize('n', [1, 2, 3, 500, 2161])
def test_the_modal_recurrence_is_lfilters(n):
    # Lightly damped (|e| near 1) to heavily damped modes, as a chain's.
    rng = np.random.default_rng(n)
    poles = np.concatenate(
        [[-0.045 + 19.2j], -rng.uniform(1e-3, 50.0, 9) + 1j * rng.uniform(1, 3e3, 9)]
    )
    e = np.exp(poles / 360.0)
    drive = rng.normal(size=(n, 10)) + 1j * rng.normal(size=(n, 10))
    expected = np.column_stack([lfilter([1.0], [1.0, -e[m]], drive[:, m]) for m in range(10)])
    found = _free_response(drive, e)
    np.testing.assert_allclose(found, expected, rtol=0.0, atol=1e-13 * np.abs(expected).max())
    assert np.array_equal(drive[0], found[0])


@pytest.mark.parametrize(
    'e',
    [
        [0.999 * np.exp(0.3j), 0.7 * np.exp(2j), 0.01, 1e-30],
        # Out of order: the dying modes first, a living one after them.
        [1e-30, 0.01, 0.7 * np.exp(2j), 0.999 * np.exp(0.3j)],
    ],
    ids=['slowest_first', 'dying_first'],
)
def test_the_doubling_scan_is_the_recurrence(e):
    e = np.asarray(e)
    rng = np.random.default_rng(3)
    g = rng.normal(size=(37, 4)) + 1j * rng.normal(size=(37, 4))
    z = np.empty_like(g)
    z[0] = g[0]
    for k in range(1, 37):
        z[k] = e * z[k - 1] + g[k]
    assert first_order_scan(g, e) == pytest.approx(z, abs=1e-13)
