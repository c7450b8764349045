"""The arm in motion as small deflections about its rigid motion, integrated modally (B.16).

The joints prescribe the rigid angles ``r(t)`` (every segment of link i turned by
``q_1 + ... + q_i``), and the springs see only the deflection ``d = phi - r``: ``K r`` and
``C r'`` are exactly the drive's ``D^T (k o(q) + c o(q'))``, so B.16 becomes

    M0 d'' + C d' + K0 d = u,
    u = g G cos phi + g G sin(phi_0) d - M(phi) r'' - (M(phi) - M0) d'' - S(phi) phi'^2,

with ``M0 = M(phi_0)`` and ``K0 = K + diag(g G sin phi_0)`` the linearization about a
reference configuration ``phi_0`` near the current one. The left-hand side is solved exactly in
its complex modal coordinates with a first-order hold on ``u`` (as
:class:`~lumpbeam_ros.model.integrate.ModalSolver` does about an equilibrium), so the stiff
springs cost nothing; ``u`` is smooth and small, and is found by waveform relaxation window by
window: propagate with the last ``u``, evaluate ``u`` on the whole window at once, repeat until
the deflections stop changing. A window's relaxation converges as fast as ``M(phi)`` stays near
``M0`` (its mass term feeds back instantly, whatever the window's length), so a window ends
before the joints turn by half :data:`RELINEARIZE_RAD`, and once a joint has moved that far
from the reference the next window takes a new linearization (an eigen-decomposition of the
``2n`` state matrix, the expensive step). While the joints are held, one linearization serves
the whole ring-down.

The modal recurrences ``z_k = e^{lambda h} z_{k-1} + g_k`` of a window are summed by doubling
(``log2`` of the window's length in array operations), not by a Python loop.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from lumpbeam_ros.model.chain import LumpedChain
from lumpbeam_ros.model.integrate import hold_weights
from lumpbeam_ros.model.modes import LinearModel

#: A new linearization when a joint angle has moved this far from the reference's, rad: 0.1
#: takes more eigen-decompositions than it saves sweeps on the bench's arm, 0.4 more sweeps.
RELINEARIZE_RAD = 0.2

#: A mode's ``e^{lambda t}`` below this is gone for the scan (double rounding).
_NEGLIGIBLE = 1e-17

#: How far the first guess of a window carries the deflections' starting rate, s.
GUESS_HORIZON_S = 0.02

#: Relaxation sweeps a window may take before the solver gives up on it.
MAX_SWEEPS = 40


@dataclass(frozen=True)
class RigidMotion:
    """The rigid angles and their first two derivatives on a time grid.

    Attributes:
        r: Rigid segment angles, (T, n).
        r_dot: Their rates, (T, n).
        r_ddot: Their accelerations, (T, n).
    """

    r: np.ndarray
    r_dot: np.ndarray
    r_ddot: np.ndarray


class _Frame:
    """The modal decomposition of one linearization, and its first-order-hold weights."""

    def __init__(self, solver: DeflectionSolver, phi_ref: np.ndarray, h: float):
        chain = solver.chain
        self.gravity_stiffness = chain.gravity_stiffness(phi_ref)
        stiffness = solver.k + np.diag(self.gravity_stiffness)
        linear = LinearModel(phi_ref, chain.mass_matrix(phi_ref), solver.c, stiffness)
        n = chain.n
        self.phi_ref = phi_ref
        self.joints = solver.joint_angles(phi_ref)
        self.mass = linear.mass
        m0_inv = np.linalg.inv(linear.mass)
        # d'' = M0^-1 (u - K0 d - C d'), rows at a time: u @ m0_inv_t - x @ decay_t.
        self.m0_inv_t = m0_inv.T
        self.decay_t = np.vstack([(m0_inv @ stiffness).T, (m0_inv @ solver.c).T])
        eigenvalues, vectors = np.linalg.eig(linear.state_matrix())
        v_inv = np.linalg.inv(vectors)
        # One of each conjugate pair (and the real modes); the state is rebuilt as 2 Re(.).
        keep = np.flatnonzero(eigenvalues.imag >= 0.0)
        # Slowest decay first: the scan drops the modes that have died out (a prefix).
        keep = keep[np.argsort(-eigenvalues[keep].real, kind='stable')]
        lam = eigenvalues[keep]
        v_t = (vectors[:, keep] * np.where(lam.imag > 0.0, 2.0, 1.0)).T
        self.v_inv = v_inv[keep]
        b_t = (self.v_inv[:, n:] @ m0_inv).T
        # Real products (a real input, a real state): half the work of complex ones.
        self.b_re, self.b_im = np.ascontiguousarray(b_t.real), np.ascontiguousarray(b_t.imag)
        self.v_re, self.v_im = np.ascontiguousarray(v_t.real), np.ascontiguousarray(-v_t.imag)
        self.e, h_phi1, h_phi2 = hold_weights(lam, h)
        self.w0 = h_phi1 - h_phi2
        self.w1 = h_phi2
        self.h = h


def _scan(g: np.ndarray, e: np.ndarray) -> np.ndarray:
    """``z_k = e z_{k-1} + g_k`` (``z_0 = g_0``) for every column, by doubling.

    The columns are ordered by decreasing ``|e|``; a pass leaves out those whose ``e^step``
    has fallen below the rounding of what it adds to (a mode that has died out).
    """
    z = g.copy()
    power = e.copy()
    step = 1
    while step < z.shape[0]:
        alive = int(np.count_nonzero(np.abs(power) > _NEGLIGIBLE))
        if alive == 0:
            break
        z[step:, :alive] += power[:alive] * z[:-step, :alive]
        power = power * power
        step *= 2
    return z


class DeflectionSolver:
    """Integrates an arm's deflections about its rigid motion, window by window.

    Args:
        chain: The arm's chain.
        joint_angles: ``phi (..., n) ->`` the angles ``M(phi)`` and gravity depend on (the
            joints': the first segment's and each link's against the one before), to decide
            where windows end and when to re-linearize.
        tol: Convergence threshold on the change of the deflections between sweeps, rad.
    """

    def __init__(
        self,
        chain: LumpedChain,
        joint_angles: Callable[[np.ndarray], np.ndarray],
        tol: float = 1e-9,
    ):
        self.chain = chain
        self.joint_angles = joint_angles
        self.tol = tol
        self.a = chain.inertia_coupling
        self.k = chain.stiffness_matrix
        self.c = chain.damping_matrix
        self.weight = chain.gravity * chain.gravity_moment
        #: Linearizations made and relaxation sweeps run so far (for the bench's report).
        self.frames = 0
        self.sweeps = 0
        self._frame: _Frame | None = None

    def _frame_for(self, phi: np.ndarray, h: float) -> _Frame:
        frame = self._frame
        if (
            frame is None
            or frame.h != h
            or np.max(np.abs(self.joint_angles(phi) - frame.joints)) > RELINEARIZE_RAD
        ):
            frame = self._frame = _Frame(self, phi, h)
            self.frames += 1
        return frame

    def _forcing(
        self,
        frame: _Frame,
        rigid: RigidMotion,
        d: np.ndarray,
        d_dot: np.ndarray,
        d_ddot: np.ndarray,
    ) -> np.ndarray:
        """``u`` of the module docstring on a window, (T, n)."""
        phi = rigid.r + d
        c, s = np.cos(phi), np.sin(phi)
        acc = rigid.r_ddot + d_ddot
        w2 = (rigid.r_dot + d_dot) ** 2
        # M(phi) x = c (A (c x)) + s (A (s x)) + I x and S(phi) w = s (A (c w)) - c (A (s w))
        # (four products: stacked into one they ran several times slower).
        a = self.a
        return np.asarray(
            self.weight * c
            + frame.gravity_stiffness * d
            + d_ddot @ frame.mass
            - self.chain.inertia * acc
            - c * ((c * acc) @ a - (s * w2) @ a)
            - s * ((s * acc) @ a + (c * w2) @ a)
        )

    def solve(
        self, d0: np.ndarray, d0_dot: np.ndarray, rigid: RigidMotion, h: float, window: int
    ) -> tuple[np.ndarray, np.ndarray] | None:
        """Deflections and their rates on a uniform grid (its first row is the start).

        Args:
            d0: Deflections at the start, rad.
            d0_dot: Their rates, rad/s.
            rigid: The rigid motion on the grid.
            h: The grid's spacing, s.
            window: Steps per relaxation window.

        Returns:
            ``(d, d_dot)``, each (T, n), or ``None`` when a window's relaxation did not
            converge (a motion too violent for small deflections).
        """
        total, n = rigid.r.shape
        d = np.empty((total, n))
        d_dot = np.empty((total, n))
        d[0], d_dot[0] = d0, d0_dot
        # A window ends before the joints turn by half the re-linearization angle in it.
        joints = self.joint_angles(rigid.r)
        start = 0
        while start < total - 1:
            drift = np.max(np.abs(joints[start + 1 : start + window + 1] - joints[start]), axis=1)
            beyond = np.flatnonzero(drift > 0.5 * RELINEARIZE_RAD)
            stop = start + 1 + max(1, int(beyond[0]) if beyond.size else drift.size)
            frame = self._frame_for(rigid.r[start] + d[start], h)
            part = RigidMotion(
                rigid.r[start:stop], rigid.r_dot[start:stop], rigid.r_ddot[start:stop]
            )
            solved = self._window(frame, part, d[start], d_dot[start])
            if solved is None:
                return None
            d[start:stop], d_dot[start:stop] = solved
            start = stop - 1
        return d, d_dot

    def _window(
        self, frame: _Frame, part: RigidMotion, d0: np.ndarray, d0_dot: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray] | None:
        """The relaxation of one window from ``(d0, d0_dot)``."""
        n = d0.size
        z0 = frame.v_inv @ np.concatenate([d0, d0_dot])
        # First guess: the deflections go on at their starting rate for a short while
        # (over a long window of free vibration, held where they start).
        elapsed = np.minimum(frame.h * np.arange(part.r.shape[0]), GUESS_HORIZON_S)
        guess = d0 + elapsed[:, None] * d0_dot
        u = self._forcing(frame, part, guess, np.broadcast_to(d0_dot, guess.shape), 0.0 * guess)
        previous = guess
        g = np.empty((part.r.shape[0], z0.size), dtype=complex)
        for _ in range(MAX_SWEEPS):
            self.sweeps += 1
            modal_u = (u @ frame.b_re) + 1j * (u @ frame.b_im)
            g[0] = z0
            g[1:] = frame.w0 * modal_u[:-1] + frame.w1 * modal_u[1:]
            # A diverging window overflows on its way to this check, which refuses it.
            with np.errstate(over='ignore', invalid='ignore'):
                z = _scan(g, frame.e)
                x = z.real @ frame.v_re + z.imag @ frame.v_im
                change = np.max(np.abs(x[:, :n] - previous))
            if not np.isfinite(change):
                return None
            d, d_dot = x[:, :n], x[:, n:]
            if change < self.tol:
                return d, d_dot
            previous = d
            with np.errstate(over='ignore', invalid='ignore'):
                d_ddot = u @ frame.m0_inv_t - x @ frame.decay_t
                u = self._forcing(frame, part, d, d_dot, d_ddot)
        return None
