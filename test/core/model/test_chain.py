"""The chain's dynamics against independent computations: geometry, energy and power."""

from dataclasses import replace

import numpy as np
import pytest

from lumpbeam_ros.core.model.chain import LumpedChain
from lumpbeam_ros.core.model.parameters import load_beam_config

BEAM, _ = load_beam_config(None)


def _chain(n_segments: int, load_kg: float = 0.0, **chain_changes) -> LumpedChain:
    chain = LumpedChain.from_beam(replace(BEAM, n_segments=n_segments), load_kg)
    return replace(chain, **chain_changes)


def _mass_positions(chain: LumpedChain, phi: np.ndarray) -> np.ndarray:
    """(x, z) of every point mass, from the joints' positions (B.17), not from the levers."""
    ls = chain.segment_lengths[0]
    steps = ls * np.stack([np.cos(phi), -np.sin(phi)], axis=-1)
    joints = np.vstack([[0.0, 0.0], np.cumsum(steps, axis=0)])
    direction = steps / ls
    centres = joints[:-1] + 0.5 * ls * direction
    tip_offset = chain.levers[-1, -1]  # L_s at the free end, L_s / 2 at the segment's centre
    tip = joints[-2] + tip_offset * direction[-1]
    return np.vstack([centres, tip])


def _numeric_jacobian(f, phi: np.ndarray, h: float = 1e-6) -> np.ndarray:
    columns = []
    for i in range(phi.size):
        step = np.zeros_like(phi)
        step[i] = h
        columns.append((f(phi + step) - f(phi - step)) / (2 * h))
    return np.stack(columns, axis=-1)


@pytest.mark.parametrize('n_segments', [1, 2, 5])
@pytest.mark.parametrize('load_kg', [0.0, 2.5])
def test_mass_matrix_is_the_point_masses_kinetic_energy(n_segments, load_kg):
    chain = _chain(n_segments, load_kg)
    phi = np.random.default_rng(n_segments).uniform(-0.4, 0.4, n_segments)
    # T = 1/2 sum_p m_p |J_p phi'|^2 + 1/2 sum_i I_i phi_i'^2, so M = sum_p m_p J_p^T J_p + I.
    jac = _numeric_jacobian(lambda p: _mass_positions(chain, p), phi)  # (masses, 2, n)
    expected = np.einsum('p,pki,pkj->ij', chain.masses, jac, jac) + np.diag(chain.inertia)
    np.testing.assert_allclose(chain.mass_matrix(phi), expected, rtol=1e-7, atol=1e-12)
    phi_ddot = np.random.default_rng(9).normal(size=n_segments)
    np.testing.assert_allclose(
        chain.inertial_forces(phi, phi_ddot), expected @ phi_ddot, rtol=1e-7, atol=1e-12
    )


def test_masses_add_up_to_the_beam_tip_and_load():
    chain = _chain(4, load_kg=1.5)
    assert chain.masses.sum() == pytest.approx(BEAM.mass_kg + BEAM.tip_mass_kg + 1.5)
    # Straight and level, each x_p = sum_i l_i^p: the G_i add up to the masses' first moment
    # about the wall, the torque gravity puts on the clamp.
    positions = _mass_positions(chain, np.zeros(4))
    assert chain.gravity_moment.sum() == pytest.approx(chain.masses @ positions[:, 0])


@pytest.mark.parametrize('n_segments', [1, 3, 6])
def test_static_forces_are_minus_the_potential_gradient(n_segments):
    chain = _chain(n_segments, load_kg=1.0, cubic_stiffness=50.0, tilt=0.02)
    phi = np.random.default_rng(1).uniform(-0.3, 0.3, n_segments)
    still = np.zeros(n_segments)
    gradient = _numeric_jacobian(lambda p: np.array(chain.energy(p, still)), phi)
    np.testing.assert_allclose(
        chain.generalized_forces(phi, still), -gradient, rtol=1e-6, atol=1e-6
    )


@pytest.mark.parametrize('n_segments', [2, 5])
@pytest.mark.parametrize('damped', [False, True])
def test_power_balance_along_the_motion(n_segments, damped):
    # dE/dt = -phi'^T C phi': an undamped chain keeps its energy, a damped one loses exactly
    # what its dampers dissipate. This checks the velocity terms (S(phi) phi'^2) of B.16.
    damping = _chain(n_segments).damping if damped else np.zeros(n_segments)
    chain = _chain(n_segments, load_kg=0.5, damping=damping)
    rng = np.random.default_rng(n_segments)
    phi, phi_dot = rng.uniform(-0.3, 0.3, n_segments), rng.uniform(-2.0, 2.0, n_segments)
    phi_ddot = chain.acceleration(phi, phi_dot)
    h = 1e-6
    later = chain.energy(phi + h * phi_dot, phi_dot + h * phi_ddot)
    earlier = chain.energy(phi - h * phi_dot, phi_dot - h * phi_ddot)
    power = (later - earlier) / (2 * h)
    dissipated = -phi_dot @ chain.damping_matrix @ phi_dot
    scale = abs(phi_dot @ chain.mass_matrix(phi) @ phi_ddot) + 1e-9
    assert power == pytest.approx(dissipated, abs=1e-6 * scale)
    if not damped:
        assert dissipated == 0.0


@pytest.mark.parametrize('angle', [0.0, 0.1, -0.25])
def test_straight_beam_tip_pose(angle):
    chain = _chain(5)
    x, z, pitch = chain.tip_pose(np.full(5, angle))
    length = chain.segment_lengths.sum()
    assert length == pytest.approx(BEAM.length_m)
    assert (x, z, pitch) == pytest.approx((length * np.cos(angle), -length * np.sin(angle), angle))


def test_tip_velocity_is_the_derivative_of_the_tip_position():
    chain = _chain(4)
    rng = np.random.default_rng(5)
    phi, phi_dot = rng.uniform(-0.3, 0.3, 4), rng.normal(size=4)
    h = 1e-6
    ahead, behind = chain.tip_pose(phi + h * phi_dot), chain.tip_pose(phi - h * phi_dot)
    numeric = [(ahead[k] - behind[k]) / (2 * h) for k in (0, 1)]
    np.testing.assert_allclose(chain.tip_velocity(phi, phi_dot), numeric, rtol=1e-6)


def test_joint_springs_act_on_relative_angles():
    # Bending one joint loads the two segments beside it, equal and opposite (B.10, B.11).
    chain = _chain(3)
    k = chain.stiffness
    phi = np.array([0.0, 0.01, 0.01])  # only joint 2 bent
    np.testing.assert_allclose(
        phi @ chain.stiffness_matrix, [-k[1] * 0.01, k[1] * 0.01, 0.0], atol=1e-12
    )
    assert chain.stiffness_matrix @ np.ones(3) == pytest.approx([k[0], 0.0, 0.0])


def test_dry_friction_opposes_joint_one_and_vanishes_at_rest():
    chain = _chain(3, coulomb_torque=0.2)
    phi = np.zeros(3)
    moving = chain.effect_forces(phi, np.array([0.5, 0.0, 0.0]))
    assert moving[0] == pytest.approx(-0.2)
    assert chain.effect_forces(phi, np.zeros(3))[0] == 0.0
    assert chain.effect_forces(phi, np.array([0.5, 0.0, 0.0]), friction=False)[0] == 0.0


def test_tip_drag_is_quadratic_and_does_negative_work():
    chain = _chain(3, drag_c_q=0.3)
    phi = np.array([0.05, 0.1, 0.12])
    slow, fast = np.array([0.1, 0.2, 0.3]), np.array([0.2, 0.4, 0.6])
    q_slow, q_fast = chain.effect_forces(phi, slow), chain.effect_forces(phi, fast)
    np.testing.assert_allclose(q_fast, 4.0 * q_slow)
    # The drag's power is -c_q |v|^3.
    speed = np.linalg.norm(chain.tip_velocity(phi, slow))
    assert q_slow @ slow == pytest.approx(-0.3 * speed**3)
