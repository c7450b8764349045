"""Linearised modes about an equilibrium: frequencies, damping ratios and mode shapes."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lumpbeam_ros.core.model.chain import LumpedChain
from lumpbeam_ros.core.model.statics import static_equilibrium


@dataclass(frozen=True)
class LinearModel:
    """B.16 linearised about an equilibrium: ``M0 d'' + C d' + K_eff d = r``.

    Attributes:
        phi_eq: The equilibrium angles.
        mass: M0 = M(phi_eq).
        damping: C.
        stiffness: K_eff = K + diag(g G sin(phi_eq + tilt)) (springs plus the gravity
            stiffness), plus the cubic spring's tangent ``3 k3 phi_1^2`` at joint 1.
    """

    phi_eq: np.ndarray
    mass: np.ndarray
    damping: np.ndarray
    stiffness: np.ndarray

    @classmethod
    def about_equilibrium(
        cls, chain: LumpedChain, phi_eq: np.ndarray | None = None
    ) -> LinearModel:
        """Linearises a chain about ``phi_eq`` (default: its static equilibrium)."""
        if phi_eq is None:
            phi_eq = static_equilibrium(chain)
        stiffness = chain.stiffness_matrix + np.diag(chain.gravity_stiffness(phi_eq))
        stiffness[0, 0] += chain.cubic_tangent(phi_eq)
        return cls(
            phi_eq=phi_eq,
            mass=chain.mass_matrix(phi_eq),
            damping=chain.damping_matrix,
            stiffness=stiffness,
        )

    def state_matrix(self) -> np.ndarray:
        """The first-order system matrix of ``[d, d']``, shape (2n, 2n)."""
        n = self.phi_eq.size
        m_inv_k = np.linalg.solve(self.mass, self.stiffness)
        m_inv_c = np.linalg.solve(self.mass, self.damping)
        return np.block([[np.zeros((n, n)), np.eye(n)], [-m_inv_k, -m_inv_c]])


@dataclass(frozen=True)
class Modes:
    """The oscillatory modes, slowest first.

    Attributes:
        natural_frequency_hz: |lambda| / 2 pi.
        damped_frequency_hz: Im(lambda) / 2 pi.
        damping_ratio: -Re(lambda) / |lambda|.
        shapes: Mode shapes in segment angles, one column per mode, normalised so the tip
            pitch component is real and positive where it is not zero.
    """

    natural_frequency_hz: np.ndarray
    damped_frequency_hz: np.ndarray
    damping_ratio: np.ndarray
    shapes: np.ndarray


def linear_modes(linear: LinearModel) -> Modes:
    """Eigen-analysis of a linearised chain (non-proportional damping allowed).

    Overdamped modes (real eigenvalues) are left out: they do not oscillate.

    Args:
        linear: The linearised model.

    Returns:
        The underdamped modes sorted by natural frequency.
    """
    n = linear.phi_eq.size
    eigenvalues, vectors = np.linalg.eig(linear.state_matrix())
    upper = eigenvalues.imag > 1e-9 * np.abs(eigenvalues).max()
    lam = eigenvalues[upper]
    shapes = vectors[:n, upper]
    order = np.argsort(np.abs(lam))
    lam, shapes = lam[order], shapes[:, order]
    ref = shapes[-1]
    phase = np.where(np.abs(ref) > 0, np.conj(ref) / np.abs(ref), 1.0)
    shapes = shapes * phase
    shapes = shapes / np.abs(shapes).max(axis=0)
    return Modes(
        natural_frequency_hz=np.abs(lam) / (2 * np.pi),
        damped_frequency_hz=lam.imag / (2 * np.pi),
        damping_ratio=-lam.real / np.abs(lam),
        shapes=shapes,
    )


def chain_modes(chain: LumpedChain) -> Modes:
    """Modes of a chain about its static equilibrium."""
    return linear_modes(LinearModel.about_equilibrium(chain))
