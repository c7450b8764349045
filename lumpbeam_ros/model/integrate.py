"""Time integration of the chain: a fast modal waveform-relaxation solver and a reference.

The fast solver splits B.16 into its linearisation about the static equilibrium and a small
nonlinear remainder ``r``:

    M0 d'' + C d' + K_eff d = r(d, d', d''),
    r = -(M(phi) - M0) phi'' - S(phi) phi'^2 + g G (cos phi - cos phi_eq + sin phi_eq d) + Q_e.

The linear part is solved exactly in its complex modal coordinates (each mode a first-order
recurrence with a first-order-hold input, run by ``scipy.signal.lfilter``); ``r`` is then
evaluated for the whole time grid at once with a few matrix products, and the two steps
alternate (waveform relaxation) until the trajectory stops changing. A beam's deflection
angles are small, so ``r`` is a fraction of a percent of the forces and a handful of sweeps
converge; when they do not (very large rotations, strong effects), the solver falls back to
the reference integrator, ``scipy.integrate.solve_ivp(method='Radau')`` on the same equations.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp
from scipy.signal import lfilter

from lumpbeam_ros.blas import single_threaded_blas
from lumpbeam_ros.model.chain import LumpedChain
from lumpbeam_ros.model.modes import LinearModel

#: Dry friction is stepped at first order (see ``_propagate_with_friction``): its grid is
#: this many times finer than the smooth dynamics need.
FRICTION_REFINEMENT = 4

#: Longest chain solved with single-threaded BLAS (see :meth:`ModalSolver.solve`).
SINGLE_THREAD_MAX_SEGMENTS = 64


@dataclass(frozen=True)
class ChainState:
    """Angles and angular velocities of the segments at one instant."""

    phi: np.ndarray
    phi_dot: np.ndarray


@dataclass(frozen=True)
class ChainSolution:
    """Angles and angular velocities on a time grid.

    Attributes:
        t: Times, s.
        phi: Angles, shape (len(t), n).
        phi_dot: Angular velocities, same shape.
        method: ``'modal'`` or ``'radau'``: which integrator produced it.
    """

    t: np.ndarray
    phi: np.ndarray
    phi_dot: np.ndarray
    method: str

    def final_state(self) -> ChainState:
        """The state at the last time."""
        return ChainState(self.phi[-1].copy(), self.phi_dot[-1].copy())


class ModalSolver:
    """The exact first-order-hold propagator of one linearised chain.

    Built once per configuration (masses, equilibrium) and reused for every stretch of
    time with that configuration: the eigen-decomposition is the expensive part.

    Args:
        chain: The chain.
        linear: Its linearisation (default: about its static equilibrium).
    """

    def __init__(self, chain: LumpedChain, linear: LinearModel | None = None):
        self.chain = chain
        self.linear = LinearModel.about_equilibrium(chain) if linear is None else linear
        n = chain.n
        self._n = n
        self._m0_inv = np.linalg.inv(self.linear.mass)
        eigenvalues, vectors = np.linalg.eig(self.linear.state_matrix())
        v_inv = np.linalg.inv(vectors)
        # A real input keeps conjugate modes conjugate: propagate one of each pair (and the
        # real, overdamped modes) and rebuild the state as 2 Re(.) (Re(.) for real modes).
        keep = eigenvalues.imag >= 0.0
        self._lam = eigenvalues[keep]
        weight = np.where(self._lam.imag > 0.0, 2.0, 1.0)
        self._v = vectors[:, keep] * weight
        self._v_inv = v_inv[keep]
        # Modal input matrix: r enters the velocity rows through M0^-1.
        self._b = self._v_inv[:, n:] @ self._m0_inv
        self._m0_inv_k = self._m0_inv @ self.linear.stiffness
        self._m0_inv_c = self._m0_inv @ self.linear.damping

    def _coefficients(self, h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``e^{lam h}`` and the first-order-hold weights ``h phi1``, ``h phi2``."""
        lam_h = self._lam * h
        e = np.exp(lam_h)
        small = np.abs(lam_h) < 1e-4
        safe = np.where(small, 1.0, lam_h)
        phi1 = np.where(small, 1.0 + lam_h / 2.0, np.expm1(lam_h) / safe)
        phi2 = np.where(small, 0.5 + lam_h / 6.0, (e - 1.0 - lam_h) / safe**2)
        return e, h * phi1, h * phi2

    def _propagate(self, z0: np.ndarray, forcing: np.ndarray, h: float) -> np.ndarray:
        """Runs every modal recurrence over a grid of spacing ``h``.

        ``z_{k+1} = e^{lam h} z_k + h (phi1 - phi2) u_k + h phi2 u_{k+1}``: the exact
        response to a forcing linear between grid points (first-order hold). With dry
        friction the recurrence is stepped by :meth:`_propagate_with_friction` instead.

        Args:
            z0: Initial modal coordinates (2n,).
            forcing: Forcing in joint space at the grid points, (T, n).
            h: Grid spacing, s.

        Returns:
            Modal coordinates at the grid points, (T, 2n).
        """
        e, h_phi1, h_phi2 = self._coefficients(h)
        u = forcing @ self._b.T
        drive = np.empty_like(u)
        drive[0] = z0
        drive[1:] = (h_phi1 - h_phi2) * u[:-1] + h_phi2 * u[1:]
        if self.chain.coulomb_torque > 0.0:
            return self._propagate_with_friction(drive, e, h_phi1)
        z: np.ndarray = np.empty_like(u)
        for m in range(self._lam.size):
            z[:, m] = lfilter([1.0], [1.0, -e[m]], drive[:, m])
        return z

    def _propagate_with_friction(
        self, drive: np.ndarray, e: np.ndarray, h_phi1: np.ndarray
    ) -> np.ndarray:
        """Steps the modal recurrence with dry friction at joint 1, decided implicitly.

        Each step holds the friction torque ``f`` constant (its exact response is
        ``h phi1 b_1 f``) and decides it on the step's mean joint-1 rate, i.e. on the
        joint-1 rotation over the step: the torque that keeps joint 1 still if it is within
        ``+-T`` (sticking), else ``-T`` against the rotation it would make (sliding). The
        work ``f * rotation`` is then never positive, so friction cannot pump energy into
        the stiff modes, whatever the step; deciding on the end-of-step rate, or smoothing
        the sign, does exactly that and chatters.

        Args:
            drive: Smooth-forcing increments per step, with the initial state in row 0.
            e: ``e^{lam h}`` per mode.
            h_phi1: ``h phi1`` per mode.

        Returns:
            Modal coordinates at the grid points.
        """
        torque = self.chain.coulomb_torque
        gamma = h_phi1 * self._b[:, 0]
        angle_row = self._v[0]  # joint 1's angle is phi_1 itself
        compliance = float((angle_row @ gamma).real)
        z = np.empty_like(drive)
        z[0] = drive[0]
        current = drive[0]
        angle = float((angle_row @ current).real)
        for k in range(1, drive.shape[0]):
            free = e * current + drive[k]
            rotation = float((angle_row @ free).real) - angle
            holding = -rotation / compliance
            f = holding if abs(holding) <= torque else -torque * np.sign(rotation)
            current = free + gamma * f
            angle = float((angle_row @ current).real)
            z[k] = current
        return z

    def solve(
        self,
        state: ChainState,
        duration: float,
        step: float,
        tol: float = 1e-11,
        max_sweeps: int = 40,
    ) -> ChainSolution | None:
        """Integrates from ``state`` over ``duration`` on a uniform grid.

        For chains up to ``SINGLE_THREAD_MAX_SEGMENTS`` the products are small, so BLAS runs
        single-threaded: handing them to threads costs more than it saves, badly so on a busy
        two-core machine. Longer chains keep the threads.

        Args:
            state: Initial angles and velocities.
            duration: Time span, s.
            step: Largest grid spacing, s (the grid is uniform, ending exactly at duration;
                ``FRICTION_REFINEMENT`` times finer with dry friction).
            tol: Convergence threshold on the change of the angles between sweeps, rad.
            max_sweeps: Sweeps before giving up.

        Returns:
            The solution on the grid (starting at 0), or ``None`` when the sweeps did not
            converge and a general integrator is needed.
        """
        if self._n > SINGLE_THREAD_MAX_SEGMENTS:
            return self._solve(state, duration, step, tol, max_sweeps)
        with single_threaded_blas():
            return self._solve(state, duration, step, tol, max_sweeps)

    def _solve(
        self, state: ChainState, duration: float, step: float, tol: float, max_sweeps: int
    ) -> ChainSolution | None:
        if self.chain.coulomb_torque > 0.0:
            step /= FRICTION_REFINEMENT
        steps = max(1, int(np.ceil(duration / step - 1e-9)))
        h = duration / steps
        t = np.linspace(0.0, duration, steps + 1)
        phi_eq = self.linear.phi_eq
        z0 = self._v_inv @ np.concatenate([state.phi - phi_eq, state.phi_dot])
        chain = self.chain
        forcing = np.zeros((t.size, self._n))
        previous = None
        for _ in range(max_sweeps):
            x = (self._propagate(z0, forcing, h) @ self._v.T).real
            if not np.all(np.isfinite(x)):
                return None
            d, d_dot = x[:, : self._n], x[:, self._n :]
            if previous is not None and np.max(np.abs(d - previous)) < tol:
                return ChainSolution(t, d + phi_eq, d_dot, 'modal')
            previous = d
            d_ddot = forcing @ self._m0_inv.T - d @ self._m0_inv_k.T - d_dot @ self._m0_inv_c.T
            phi = d + phi_eq
            # r: everything B.16 has beyond its linearisation (see the module docstring).
            # The equilibrium's own forces cancel, leaving the linear model's -K_eff d - C d'.
            inertial_excess = chain.inertial_forces(phi, d_ddot) - d_ddot @ self.linear.mass
            linear_force = -d @ self.linear.stiffness - d_dot @ self.linear.damping
            forcing = (
                chain.generalized_forces(phi, d_dot, friction=False)
                - linear_force
                - inertial_excess
            )
        return None


def solve_reference(
    chain: LumpedChain,
    state: ChainState,
    t_eval: np.ndarray,
    rtol: float = 1e-10,
    atol: float = 1e-12,
) -> ChainSolution:
    """Integrates B.16 with ``solve_ivp(method='Radau')``: the general, slow reference.

    Args:
        chain: The chain.
        state: Initial state at ``t_eval[0]``.
        t_eval: Output times, increasing.
        rtol: Relative tolerance.
        atol: Absolute tolerance.

    Returns:
        The solution at ``t_eval``.

    Raises:
        RuntimeError: The integrator failed.
    """
    n = chain.n

    def rhs(_t: float, y: np.ndarray) -> np.ndarray:
        return np.concatenate([y[n:], chain.acceleration(y[:n], y[n:])])

    y0 = np.concatenate([state.phi, state.phi_dot])
    result = solve_ivp(
        rhs, (t_eval[0], t_eval[-1]), y0, method='Radau', t_eval=t_eval, rtol=rtol, atol=atol
    )
    if not result.success:
        raise RuntimeError(f'reference integration failed: {result.message}')
    return ChainSolution(t_eval, result.y[:n].T, result.y[n:].T, 'radau')
