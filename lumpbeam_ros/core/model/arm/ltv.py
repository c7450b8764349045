"""The arm in motion as small deflections about its rigid motion, integrated modally (B.16).

The joints prescribe the rigid angles ``r(t)`` (every segment of link i turned by
``q_1 + ... + q_i``), and the springs see only the deflection ``d = phi - r``: ``K r`` and
``C r'`` are exactly the drive's ``D^T (k o(q) + c o(q'))``, so B.16 becomes

    M0 d'' + C d' + K0 d = u,
    u = g G cos phi + g G sin(phi_0) d - M(phi) r'' - (M(phi) - M0) d'' - S(phi) phi'^2,

with ``M0 = M(phi_0)`` and ``K0 = K + diag(g G sin phi_0)`` the linearization about a
reference configuration ``phi_0`` near the current one. The left-hand side is solved exactly in
its complex modal coordinates, ``u`` held as the parabola through the grid points before, at
and after each step (a first-order hold, as
:class:`~lumpbeam_ros.core.model.integrate.ModalSolver` does about an equilibrium, on a piece's
first step), so the stiff springs cost nothing; ``u`` is smooth and small, and is found by
waveform relaxation window by window: propagate with the last ``u``, evaluate ``u`` on the
whole window at once, repeat until the deflections' error, estimated from how fast the
sweeps contract, is below the tolerance. A window's relaxation converges as fast as
``M(phi)`` stays near ``M0`` (its mass term feeds back instantly, whatever the window's
length), so a window ends before the joints turn by half :data:`RELINEARIZE_RAD`, and a new
linearization (an eigen-decomposition of the ``2n`` state matrix, the expensive step) is
taken at the end of the window that would stray further from the last one, so it serves
that window and the next from the middle. While the joints are held, one linearization
serves the whole ring-down.

The modal recurrences ``z_k = e^{lambda h} z_{k-1} + g_k`` of a window are summed by doubling
(``log2`` of the window's length in array operations), not by a Python loop; the oscillating
modes in complex numbers, the overdamped ones in real. A sweep's cost is array arithmetic
over the window, so the rigid angles' cosines and sines are taken once a window and the
deflections' by their series.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from lumpbeam_ros.core.model.chain import LumpedChain
from lumpbeam_ros.core.model.integrate import first_order_scan, hold_weights
from lumpbeam_ros.core.model.modes import LinearModel

#: Joint travel a linearization serves (half of it on either side), rad. On the bench's arm
#: 0.4 took the fewest sweeps and was the most accurate; 0.2, 0.3 and 0.6 were up to three
#: times less accurate (0.06 to 0.09 um RMS: the hold samples the forcing, which carries
#: ``(M(phi) - M0) d''``, differently) and 0.8 took more sweeps.
RELINEARIZE_RAD = 0.4

#: A jump of the rates at a piece's start at least this large is a kick (a knot), rad/s.
KICK_RAD_S = 1e-6

#: How far the first guess of a window carries the deflections' starting rate, s.
GUESS_HORIZON_S = 0.02

#: Largest deflection whose cosine and sine are taken by their series, rad.
SERIES_RAD = 0.15

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
        # The overdamped modes apart, in real arithmetic: half the work of complex numbers.
        real = lam.imag == 0.0
        self.oscillating = _Modes(lam[~real], b_t[:, ~real], v_t[~real], h)
        self.overdamped = _Modes(lam[real].real, b_t[:, real].real, v_t[real].real, h)
        self.split = real
        self.h = h


class _Modes:
    """Modes of a frame (all complex or all real) and their hold weights.

    Args:
        lam: Eigenvalues, slowest decay first (the scan drops the modes that have died out).
        b_t: Input matrix: a forcing row times it is the modes' input, (n, m).
        v_t: Output matrix: the modes times it are the state ``[d, d']``, (m, 2n).
        h: Step, s.
    """

    def __init__(self, lam: np.ndarray, b_t: np.ndarray, v_t: np.ndarray, h: float):
        self.is_complex = bool(np.iscomplexobj(lam))
        self.m = lam.size
        self.e, h_phi1, h_phi2 = hold_weights(lam, h)
        h_phi3 = _h_phi3(lam, h)
        if not self.is_complex:
            self.e, h_phi1, h_phi2, h_phi3 = (w.real for w in (self.e, h_phi1, h_phi2, h_phi3))
        # The first step: a first-order hold; the others: the parabola through the samples
        # before, at and after the step (O(h^3) globally instead of O(h^2)).
        self.w0 = h_phi1 - h_phi2
        self.w1 = h_phi2
        self.q_before = h_phi3 - 0.5 * h_phi2
        q_at = h_phi1 - 2.0 * h_phi3
        q_after = h_phi3 + 0.5 * h_phi2
        # A real input times a complex matrix as one real product whose result, read as
        # complex, is the modal input: the columns interleave real and imaginary parts. The
        # hold's weights are folded in, so a sweep's three weighted inputs are one product.
        self.b = _interleaved(b_t) if self.is_complex else b_t
        self.b_weighted = np.hstack([self._real(b_t * w) for w in (self.q_before, q_at, q_after)])
        # And back: Re(z v) = [Re z, Im z] interleaved times the rows of Re v and -Im v.
        self.v = np.empty((2 * self.m, v_t.shape[1])) if self.is_complex else v_t
        if self.is_complex:
            self.v[0::2], self.v[1::2] = v_t.real, -v_t.imag

    def _real(self, b: np.ndarray) -> np.ndarray:
        return _interleaved(b) if self.is_complex else b

    def product(self, u: np.ndarray, b: np.ndarray) -> np.ndarray:
        """``u @ b`` read as the modes' numbers."""
        out = np.asarray(u @ b)
        return out.view(complex) if self.is_complex else out

    def state(
        self, u: np.ndarray, z0: np.ndarray, before: np.ndarray | None, g: np.ndarray
    ) -> np.ndarray:
        """These modes' part of ``[d, d']`` on a window under the forcing ``u``.

        Args:
            u: The forcing, (T, n).
            z0: The modes at the window's start.
            before: The forcing one step before the start, or ``None`` (a first-order hold
                on the first step).
            g: Room for the modes, (T, m).
        """
        m = self.m
        if m == 0:
            return np.zeros((u.shape[0], self.v.shape[1]))
        weighted = self.product(u, self.b_weighted)
        w_before, w_at, w_after = weighted[:, :m], weighted[:, m : 2 * m], weighted[:, 2 * m :]
        g[0] = z0
        if before is None:
            modal = self.product(u[:2], self.b)
            g[1] = self.w0 * modal[0] + self.w1 * modal[1]
        else:
            g[1] = self.q_before * self.product(before, self.b) + w_at[0] + w_after[1]
        np.add(w_before[:-2], w_at[1:-1], out=g[2:])
        g[2:] += w_after[2:]
        z = first_order_scan(g, self.e)
        return np.asarray((z.view(float) if self.is_complex else z) @ self.v)


def _h_phi3(lam: np.ndarray, h: float) -> np.ndarray:
    """``h phi3(lam h)``, ``phi3(z) = (e^z - 1 - z - z^2 / 2) / z^3`` (its series when small)."""
    z = lam * h
    small = np.abs(z) < 0.05
    safe = np.where(small, 1.0, z)
    series = 1.0 / 6.0 + z * (1.0 / 24.0 + z * (1.0 / 120.0 + z * (1.0 / 720.0 + z / 5040.0)))
    return np.asarray(h * np.where(small, series, (np.expm1(z) - z - 0.5 * z * z) / safe**3))


def _turned(trig: tuple[np.ndarray, np.ndarray], d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``cos(r + d)`` and ``sin(r + d)`` from ``cos r``, ``sin r`` and a small ``d``.

    The trigonometric functions of a sweep's angles cost more than the rest of its forcing;
    the rigid angles' are taken once a window and the deflections' by their Taylor series,
    which for ``|d| <=`` :data:`SERIES_RAD` ends below ``2e-15`` after the ``d^9`` term.
    """
    cos_r, sin_r = trig
    if np.max(np.abs(d)) > SERIES_RAD:
        cos_d, sin_d = np.cos(d), np.sin(d)
    else:
        d2 = d * d
        cos_d = _horner(d2, (1.0 / 40320.0, -1.0 / 720.0, 1.0 / 24.0, -0.5, 1.0))
        sin_d = _horner(d2, (1.0 / 362880.0, -1.0 / 5040.0, 1.0 / 120.0, -1.0 / 6.0, 1.0))
        sin_d *= d
    c = cos_r * cos_d
    s = sin_r * cos_d
    product = sin_r * sin_d
    c -= product
    np.multiply(cos_r, sin_d, out=product)
    s += product
    return c, s


def _horner(x: np.ndarray, coefficients: tuple[float, ...]) -> np.ndarray:
    """The polynomial in ``x`` with ``coefficients`` (highest power first), in place."""
    out = coefficients[0] * x
    for coefficient in coefficients[1:-1]:
        out += coefficient
        out *= x
    out += coefficients[-1]
    return out


def _interleaved(b: np.ndarray) -> np.ndarray:
    """A complex (n, m) matrix as a real (n, 2m) one, each column's real then imaginary part.

    A real row vector times it is, read as complex (``.view(complex)``), the row times ``b``.
    """
    out = np.empty((b.shape[0], 2 * b.shape[1]))
    out[:, 0::2], out[:, 1::2] = b.real, b.imag
    return out


class DeflectionSolver:
    """Integrates an arm's deflections about its rigid motion, window by window.

    Args:
        chain: The arm's chain.
        joint_angles: ``phi (..., n) ->`` the angles ``M(phi)`` and gravity depend on (the
            joints': the first segment's and each link's against the one before), to decide
            where windows end and when to re-linearize.
        tol: Convergence threshold on the deflections' estimated error (a sweep's change
            times its ratio to the last one's), or on their change between sweeps, rad.
    """

    def __init__(
        self,
        chain: LumpedChain,
        joint_angles: Callable[[np.ndarray], np.ndarray],
        tol: float = 1e-8,
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

    def _frame_for(self, joints: np.ndarray, phi_ahead: np.ndarray, h: float) -> _Frame:
        """The linearization for a window whose joint angles are ``joints``.

        The last one serves while the window stays within about half :data:`RELINEARIZE_RAD`
        of it (a window spans less than that, and the deflections move on a little); a new one
        is taken at ``phi_ahead``, the window's end, so it serves this window and the next one
        from the middle (the relaxation converges as fast as the joints stay near the
        linearization's).
        """
        frame = self._frame
        if (
            frame is None
            or frame.h != h
            or np.max(np.abs(joints - frame.joints)) > 0.6 * RELINEARIZE_RAD
        ):
            frame = self._frame = _Frame(self, phi_ahead, h)
            self.frames += 1
        return frame

    def _forcing(
        self,
        frame: _Frame,
        rigid: RigidMotion,
        trig: tuple[np.ndarray, np.ndarray],
        d: np.ndarray,
        d_dot: np.ndarray,
        d_ddot: np.ndarray,
    ) -> np.ndarray:
        """``u`` of the module docstring on a window, (T, n); ``trig``: cos and sin of ``r``."""
        c, s = _turned(trig, d)
        acc = rigid.r_ddot + d_ddot
        w2 = rigid.r_dot + d_dot
        w2 *= w2
        # M(phi) x = c (A (c x)) + s (A (s x)) + I x and S(phi) w = s (A (c w)) - c (A (s w)):
        # the products by A taken two at a time (stacked into one they ran several times
        # slower), in place where the arrays are the window's size.
        cos_part = c * acc
        cos_part -= s * w2
        sin_part = s * acc
        sin_part += c * w2
        u = self.weight - cos_part @ self.a
        u *= c
        sin_part = sin_part @ self.a
        sin_part *= s
        u -= sin_part
        u += frame.gravity_stiffness * d
        u += d_ddot @ frame.mass
        acc *= self.chain.inertia
        u -= acc
        return np.asarray(u)

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
        # The last window's frame and forcing, for the point before the next one's start.
        last: tuple[_Frame, np.ndarray] | None = None
        while start < total - 1:
            drift = np.max(np.abs(joints[start + 1 : start + window + 1] - joints[start]), axis=1)
            beyond = np.flatnonzero(drift > 0.5 * RELINEARIZE_RAD)
            stop = start + 1 + max(1, int(beyond[0]) if beyond.size else drift.size)
            # The window's joint angles, the deflections' part taken as at its start.
            bent = joints[start:stop] + self.joint_angles(d[start])
            # A new linearization is taken at the window's end, so that it serves from the
            # middle, except on a piece's first window when the rates jump there (a kick):
            # the kick's fast accelerations, times the mass matrix's change from the
            # linearization's, would then fill the forcing that the hold samples.
            ahead = stop - 1 if start or np.max(np.abs(d0_dot)) < KICK_RAD_S else 0
            frame = self._frame_for(bent, rigid.r[ahead] + d[start], h)
            part = RigidMotion(
                rigid.r[start:stop], rigid.r_dot[start:stop], rigid.r_ddot[start:stop]
            )
            before = None
            if last is not None:
                before = _reframed(last[0], frame, last[1], d[start - 1], d_dot[start - 1])
            solved = self._window(frame, part, d[start], d_dot[start], before)
            if solved is None:
                return None
            d[start:stop], d_dot[start:stop], u = solved
            last = (frame, u[-2])
            start = stop - 1
        return d, d_dot

    def _window(
        self,
        frame: _Frame,
        part: RigidMotion,
        d0: np.ndarray,
        d0_dot: np.ndarray,
        before: np.ndarray | None,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """The relaxation of one window from ``(d0, d0_dot)``.

        Args:
            frame: The linearization.
            part: The rigid motion over the window.
            d0: Deflections at its start.
            d0_dot: Their rates.
            before: The forcing one step before the start, in this frame (the last window's,
                converged), for the first step's parabola; ``None``: a first-order hold.

        Returns:
            ``(d, d_dot, u)`` on the window, or ``None`` when it did not converge.
        """
        n = d0.size
        z0 = frame.v_inv @ np.concatenate([d0, d0_dot])
        z0_overdamped = z0[frame.split].real
        z0 = z0[~frame.split]
        # First guess: the deflections go on at their starting rate for a short while
        # (over a long window of free vibration, held where they start).
        steps = part.r.shape[0]
        elapsed = np.minimum(frame.h * np.arange(steps), GUESS_HORIZON_S)
        guess = d0 + elapsed[:, None] * d0_dot
        trig = (np.cos(part.r), np.sin(part.r))
        u = self._forcing(
            frame, part, trig, guess, np.broadcast_to(d0_dot, guess.shape), 0.0 * guess
        )
        previous = guess
        g = np.empty((steps, z0.size), dtype=complex)
        g_overdamped = np.empty((steps, z0_overdamped.size))
        last_change = 0.0
        for sweep in range(MAX_SWEEPS):
            self.sweeps += 1
            # A diverging window overflows on its way to this check, which refuses it.
            with np.errstate(over='ignore', invalid='ignore'):
                x = frame.oscillating.state(u, z0, before, g)
                x += frame.overdamped.state(u, z0_overdamped, before, g_overdamped)
                change = np.max(np.abs(x[:, :n] - previous))
            if not np.isfinite(change):
                return None
            d, d_dot = x[:, :n], x[:, n:]
            # Each sweep shrinks the error by about the ratio of its change to the last one's
            # (the first change, from the guess, says nothing of that ratio), so this sweep's
            # deflections are off by about that ratio times its change.
            # (Its square root, not the change squared: a change near 1e155 would overflow.)
            if change < self.tol or change < math.sqrt(self.tol * last_change):
                return d, d_dot, u
            last_change = change if sweep else 0.0
            previous = d
            with np.errstate(over='ignore', invalid='ignore'):
                d_ddot = u @ frame.m0_inv_t - x @ frame.decay_t
                u = self._forcing(frame, part, trig, d, d_dot, d_ddot)
        return None


def _reframed(
    old: _Frame, new: _Frame, u: np.ndarray, d: np.ndarray, d_dot: np.ndarray
) -> np.ndarray:
    """A converged forcing of ``old``'s linearization in ``new``'s.

    ``u`` holds the linear model's own ``K0 d`` and ``M0 d''`` terms (module docstring), so
    a new linearization moves it by the difference of those, with ``d''`` the converged one.
    """
    if new is old:
        return u
    d_ddot = u @ old.m0_inv_t - np.concatenate([d, d_dot]) @ old.decay_t
    return np.asarray(
        u + (new.gravity_stiffness - old.gravity_stiffness) * d + d_ddot @ (new.mass - old.mass)
    )
