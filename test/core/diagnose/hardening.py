"""A discrepancy outside the effect library, for tests only: a cubic hardening clamp spring.

The clamp's torque gains ``-k3 (phi_1 - phi_ref)^3`` about the unloaded rest angle
``phi_ref``, so the beam stiffens with the swing and its frequency falls as the decay dies
out: no effect of doc/interfaces.md does that. At rest after the drop the beam sits exactly
where the nominal model puts it; only the loaded rest and the dynamics differ.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from lumpbeam_ros.core.model.chain import LumpedChain
from lumpbeam_ros.core.model.integrate import ChainState, ModalSolver, solve_reference
from lumpbeam_ros.core.model.modes import LinearModel
from lumpbeam_ros.core.model.parameters import BeamParameters, DropTestConfig
from lumpbeam_ros.core.model.statics import static_equilibrium
from lumpbeam_ros.core.model.trajectory import TipTrajectory

STEP_S = 1.0 / 360.0


@dataclass(frozen=True)
class HardeningChain(LumpedChain):
    """A chain whose clamp spring hardens: torque ``-k phi_1 - k3 (phi_1 - phi_ref)^3``."""

    cubic_nm_per_rad3: float = 0.0
    reference_rad: float = 0.0

    def generalized_forces(self, phi, phi_dot, friction=True, cs=None):
        q = super().generalized_forces(phi, phi_dot, friction, cs)
        q[..., 0] -= self.cubic_nm_per_rad3 * (phi[..., 0] - self.reference_rad) ** 3
        return q


def _equilibrium(chain: HardeningChain) -> np.ndarray:
    """Newton on B.16 at rest with the cubic term (from the linear chain's equilibrium)."""
    phi = static_equilibrium(chain)
    for _ in range(50):
        residual = chain.generalized_forces(phi, np.zeros_like(phi))
        step = np.linalg.solve(_stiffness(chain, phi), residual)
        phi = phi + step
        if np.max(np.abs(step)) < 1e-14:
            break
    return phi


def _stiffness(chain: HardeningChain, phi: np.ndarray) -> np.ndarray:
    """-dQ/dphi at rest: springs, gravity and the cubic term's tangent."""
    k = chain.stiffness_matrix + np.diag(chain.gravity * chain.gravity_moment * np.sin(phi))
    k[0, 0] += 3.0 * chain.cubic_nm_per_rad3 * (phi[0] - chain.reference_rad) ** 2
    return k


def simulate_hardening_drop(
    beam: BeamParameters, drop: DropTestConfig, cubic: float, rate_hz: float = 180.0
) -> TipTrajectory:
    """The drop test of a beam with a hardening clamp: at rest loaded, then released."""
    free = HardeningChain(**vars(LumpedChain.from_beam(beam, 0.0)))
    free = replace(free, cubic_nm_per_rad3=cubic, reference_rad=static_equilibrium(free)[0])
    loaded = HardeningChain(**vars(LumpedChain.from_beam(beam, drop.load_kg)))
    loaded = replace(loaded, cubic_nm_per_rad3=cubic, reference_rad=free.reference_rad)
    phi0 = _equilibrium(loaded)
    count = int(np.floor(drop.duration_s * rate_hz + 1e-9)) + 1
    t = np.arange(count) / rate_hz
    # Linearised about the hardened equilibrium, so the cubic term's tangent is not left to
    # the waveform relaxation (which diverges when it is large).
    free_eq = _equilibrium(free)
    linear = replace(
        LinearModel.about_equilibrium(free, free_eq), stiffness=_stiffness(free, free_eq)
    )
    solution = ModalSolver(free, linear).solve(
        ChainState(phi0, np.zeros(beam.n_segments)), drop.duration_s - drop.release_time_s, STEP_S
    )
    if solution is None:  # too nonlinear for the waveform relaxation
        grid = np.arange(0.0, drop.duration_s - drop.release_time_s + 0.5 * STEP_S, STEP_S)
        solution = solve_reference(free, ChainState(phi0, np.zeros(beam.n_segments)), grid)
    after = t >= drop.release_time_s
    phi = np.repeat(phi0[None, :], count, axis=0)
    grid_t = solution.t + drop.release_time_s
    for i in range(beam.n_segments):
        phi[after, i] = np.interp(t[after], grid_t, solution.phi[:, i])
    x, z, pitch = free.tip_pose(phi)
    load = np.where(after, 0.0, drop.load_kg)
    return TipTrajectory(t=t, x=x, z=z, pitch=pitch, load_kg=load, q=phi)
