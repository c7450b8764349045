"""Time integration of the chain: a fast modal waveform-relaxation solver and a reference.

The fast solver splits B.16 into its linearisation about the static equilibrium and a small
nonlinear remainder ``r``:

    M0 d'' + C d' + K_eff d = r(d, d', d''),
    r = -(M(phi) - M0) phi'' - S(phi) phi'^2 + g G (cos phi - cos phi_eq + sin phi_eq d) + Q_e.

The linear part is solved exactly in its complex modal coordinates (each mode a first-order
recurrence with a first-order-hold input, run as a doubling scan); ``r`` is then
evaluated for the whole time grid at once with a few matrix products, and the two steps
alternate (waveform relaxation) until the trajectory stops changing. A beam's deflection
angles are small, so ``r`` is a fraction of a percent of the forces and a handful of sweeps
converge; when they do not (very large rotations, strong effects), the solver falls back to
the reference integrator, ``scipy.integrate.solve_ivp(method='Radau')`` on the same equations.
"""

from __future__ import annotations

import math
from contextlib import nullcontext
from dataclasses import dataclass

import numpy as np

from lumpbeam_ros.base.blas import single_threaded_blas
from lumpbeam_ros.base.errors import SolverBudgetError
from lumpbeam_ros.core.model.chain import LumpedChain, trig
from lumpbeam_ros.core.model.modes import LinearModel

#: Dry friction is stepped at first order (see ``_propagate_with_friction``): its grid is
#: this many times finer than the smooth dynamics need (the remainder ``r`` stays on the
#: coarse grid).
FRICTION_REFINEMENT = 4

#: Largest ratio of successive sweeps' changes taken as a contraction, from which the next
#: change is predicted (:func:`_converged`).
CONTRACTION = 0.5

#: A contraction carried over from a similar solve is taken this many times larger: the
#: beams of a fit's successive simulations differ a little, their contractions too.
CONTRACTION_MARGIN = 3.0

#: Longest chain solved with single-threaded BLAS (see :meth:`ModalSolver.solve`).
SINGLE_THREAD_MAX_SEGMENTS = 64

#: The Radau reference's budget: at any time it may have spent this many right-hand-side
#: evaluations per second simulated so far (a drop test of the paper's beam takes about
#: 54000 at rtol 1e-10) ...
REFERENCE_EVALUATIONS_PER_S = 200_000
#: ... plus this many. Equations too stiff to simulate spend them in the first milliseconds.
REFERENCE_MIN_EVALUATIONS = 10_000


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
        remainder: The modal solver's converged nonlinear remainder ``r`` on the grid,
            (len(t), n), to start a similar solve from (``None`` for Radau).
        contraction: The largest ratio of successive sweeps' changes the modal solver saw
            (or was given), for a similar solve (:meth:`ModalSolver.solve`); NaN if none.
    """

    t: np.ndarray
    phi: np.ndarray
    phi_dot: np.ndarray
    method: str
    remainder: np.ndarray | None = None
    contraction: float = math.nan

    def final_state(self) -> ChainState:
        """The state at the last time."""
        return ChainState(self.phi[-1].copy(), self.phi_dot[-1].copy())


def hold_weights(lam: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``e^{lam h}`` and the first-order-hold weights ``h phi1(lam h)``, ``h phi2(lam h)``.

    The exact response of ``z' = lam z + u`` to a ``u`` linear over a step of ``h`` is
    ``z_{k+1} = e^{lam h} z_k + h (phi1 - phi2) u_k + h phi2 u_{k+1}``.
    """
    lam_h = lam * h
    e = np.exp(lam_h)
    small = np.abs(lam_h) < 1e-4
    safe = np.where(small, 1.0, lam_h)
    phi1 = np.where(small, 1.0 + lam_h / 2.0, np.expm1(lam_h) / safe)
    phi2 = np.where(small, 0.5 + lam_h / 6.0, (e - 1.0 - lam_h) / safe**2)
    return e, h * phi1, h * phi2


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

    def modal_state(self, state: ChainState) -> np.ndarray:
        """The modal coordinates of a state (one of each conjugate pair)."""
        return np.asarray(
            self._v_inv @ np.concatenate([state.phi - self.linear.phi_eq, state.phi_dot])
        )

    def friction_recurrence(self, h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """What :func:`friction_steps` needs for a grid of spacing ``h``.

        Returns:
            ``e^{lam h}`` per mode, the modal response ``gamma`` to a unit joint-1 torque
            held over a step, and the row whose real product with the modal coordinates is
            joint 1's angle.
        """
        e, h_phi1, _ = self._coefficients(h)
        return e, h_phi1 * self._b[:, 0], self._v[0]

    def _coefficients(self, h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``e^{lam h}`` and the first-order-hold weights ``h phi1``, ``h phi2``."""
        return hold_weights(self._lam, h)

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
        u = forcing @ self._b.T
        if self.chain.coulomb_torque > 0.0:
            return self._propagate_with_friction(z0, u, h)
        e, h_phi1, h_phi2 = self._coefficients(h)
        return _free_response(_hold_drive(z0, u, h_phi1, h_phi2), e)

    def _propagate_with_friction(self, z0: np.ndarray, u: np.ndarray, h: float) -> np.ndarray:
        """Steps the modal recurrence with dry friction at joint 1 (:func:`friction_steps`).

        On a grid ``FRICTION_REFINEMENT`` times finer than ``h``, the modal forcing ``u``
        interpolated linearly between the coarse points: that is the first-order hold the
        coarse grid assumes, so the finer grid only serves the friction's decisions, and the
        remainder (most of a sweep's work) is evaluated on the coarse grid alone.

        Args:
            z0: Initial modal coordinates.
            u: Modal forcing at the coarse grid points, (T, m).
            h: Coarse grid spacing, s.

        Returns:
            Modal coordinates at the coarse grid points, (T, m).
        """
        fine = FRICTION_REFINEMENT
        e, h_phi1, h_phi2 = self._coefficients(h / fine)
        # Fine step j of coarse step k holds u_k + (j + s) / fine (u_{k+1} - u_k), s in [0, 1].
        j = np.arange(fine)[:, None]
        on_change = ((h_phi1 - h_phi2) * j + h_phi2 * (j + 1)) / fine  # (fine, m)
        change = u[1:] - u[:-1]
        count, m = u.shape
        drive = np.empty(((count - 1) * fine + 1, m), dtype=complex)
        drive[0] = z0
        np.add(  # the steps, (T - 1, fine, m), written in place
            h_phi1 * u[:-1, None, :],
            on_change * change[:, None, :],
            out=drive[1:].reshape(count - 1, fine, m),
        )
        gamma = h_phi1 * self._b[:, 0]
        z = friction_steps(drive, e, gamma, self._v[0], self.chain.coulomb_torque)
        return z[::fine]

    def solve(
        self,
        state: ChainState,
        duration: float,
        step: float,
        tol: float = 1e-11,
        max_sweeps: int = 40,
        remainder: np.ndarray | None = None,
        contraction: float = math.nan,
    ) -> ChainSolution | None:
        """Integrates from ``state`` over ``duration`` on a uniform grid.

        For chains up to ``SINGLE_THREAD_MAX_SEGMENTS`` the products are small, so BLAS runs
        single-threaded: handing them to threads costs more than it saves, badly so on a busy
        two-core machine. Longer chains keep the threads.

        The sweeps start from ``remainder`` when given (a nearby beam's converged one, e.g.
        the previous step of a fit): the fixed point is the same, to ``tol``, and it is
        reached in fewer sweeps than from zero. A warm start that does not converge is
        retried from zero, so it can only save sweeps.

        Args:
            state: Initial angles and velocities.
            duration: Time span, s.
            step: Largest grid spacing, s (the grid is uniform, ending exactly at duration;
                dry friction is decided on one ``FRICTION_REFINEMENT`` times finer).
            tol: Convergence threshold on the change of the angles between sweeps, or on
                the next sweep's change once the sweeps show their contraction
                (:func:`_converged`), rad.
            max_sweeps: Sweeps before giving up.
            remainder: A starting remainder on the same grid (ignored if its shape differs).
            contraction: The contraction the solve that left ``remainder`` showed
                (:attr:`ChainSolution.contraction`): with it, the change the third sweep
                would make is predicted from the second's (:func:`_converged`).

        Returns:
            The solution on the grid (starting at 0), or ``None`` when the sweeps did not
            converge and a general integrator is needed.
        """
        threads = nullcontext() if self._n > SINGLE_THREAD_MAX_SEGMENTS else single_threaded_blas()
        with threads:
            solution = self._solve(state, duration, step, tol, max_sweeps, remainder, contraction)
            if solution is None and remainder is not None:
                solution = self._solve(state, duration, step, tol, max_sweeps, None, math.nan)
        return solution

    def _solve(
        self,
        state: ChainState,
        duration: float,
        step: float,
        tol: float,
        max_sweeps: int,
        remainder: np.ndarray | None,
        contraction: float,
    ) -> ChainSolution | None:
        steps = max(1, int(np.ceil(duration / step - 1e-9)))
        h = duration / steps
        t = np.linspace(0.0, duration, steps + 1)
        phi_eq = self.linear.phi_eq
        z0 = self.modal_state(state)
        chain = self.chain
        shape = (t.size, self._n)
        warm = remainder is not None and remainder.shape == shape
        forcing = np.array(remainder) if warm else np.zeros(shape)
        previous = None
        change = math.inf
        seen = math.nan  # the largest ratio of successive changes
        for _ in range(max_sweeps):
            # A diverging sweep overflows on its way to the check below, which handles it.
            with np.errstate(over='ignore', invalid='ignore'):
                x = (self._propagate(z0, forcing, h) @ self._v.T).real
            if not np.all(np.isfinite(x)):
                return None
            d, d_dot = x[:, : self._n], x[:, self._n :]
            if previous is not None:
                last, change = change, float(np.max(np.abs(d - previous)))
                if math.isfinite(last):
                    seen = max(change / last, seen) if math.isfinite(seen) else change / last
                if _converged(change, last, tol, contraction):
                    shown = seen if math.isfinite(seen) else contraction
                    return ChainSolution(t, d + phi_eq, d_dot, 'modal', forcing, shown)
            previous = d
            d_ddot = forcing @ self._m0_inv.T - d @ self._m0_inv_k.T - d_dot @ self._m0_inv_c.T
            phi = d + phi_eq
            cs = trig(phi)  # shared by every force term below
            # r: everything B.16 has beyond its linearisation (see the module docstring).
            # The equilibrium's own forces cancel, leaving the linear model's -K_eff d - C d'.
            # A diverging sweep's large but finite angles may overflow here: the next
            # sweep's check refuses them.
            with np.errstate(over='ignore', invalid='ignore'):
                inertial_excess = (
                    chain.inertial_forces(phi, d_ddot, cs) - d_ddot @ self.linear.mass
                )
                linear_force = -d @ self.linear.stiffness - d_dot @ self.linear.damping
                forcing = (
                    chain.generalized_forces(phi, d_dot, friction=False, cs=cs)
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
        SolverBudgetError: It fell behind its budget: more than
            :data:`REFERENCE_MIN_EVALUATIONS` + :data:`REFERENCE_EVALUATIONS_PER_S` evaluations
            per second simulated so far. The equations are too stiff or unstable to simulate
            (they would run for hours).
    """
    # Imported here: the modal solver, which nearly every simulation ends in, needs no scipy,
    # and importing it would cost `lumpbeam analyze` (whose backbone simulates) its start-up.
    from scipy.integrate import solve_ivp

    n = chain.n
    t0 = float(t_eval[0])
    duration = float(t_eval[-1]) - t0
    spent = 0

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        nonlocal spent
        spent += 1
        if spent > REFERENCE_MIN_EVALUATIONS + REFERENCE_EVALUATIONS_PER_S * (t - t0):
            raise _OverBudgetError(t)
        return np.concatenate([y[n:], chain.acceleration(y[:n], y[n:])])

    y0 = np.concatenate([state.phi, state.phi_dot])
    try:
        with np.errstate(over='ignore', invalid='ignore'):  # a failed step is retried smaller
            result = solve_ivp(
                rhs,
                (t_eval[0], t_eval[-1]),
                y0,
                method='Radau',
                t_eval=t_eval,
                rtol=rtol,
                atol=atol,
            )
    except _OverBudgetError as stop:
        raise SolverBudgetError(
            f'the reference integrator spent {spent - 1} evaluations on {stop.args[0] - t0:.3g} '
            f'of {duration:.3g} s (its budget: {REFERENCE_MIN_EVALUATIONS} + '
            f'{REFERENCE_EVALUATIONS_PER_S} per simulated s): the beam is too stiff or unstable '
            'to simulate (extreme parameters)'
        ) from None
    if not result.success:
        raise RuntimeError(f'reference integration failed: {result.message}')
    return ChainSolution(t_eval, result.y[:n].T, result.y[n:].T, 'radau')


class _OverBudgetError(Exception):
    """Raised from inside ``solve_ivp`` when the evaluations run out; carries the time."""


def _converged(change: float, last: float, tol: float, expected: float = math.nan) -> bool:
    """Whether the sweeps have converged: the angles' change below ``tol``, or the next one.

    The sweeps contract geometrically (by 1e-3 to 3e-2 a sweep): once the last two changes
    show it, the next change, ``change * (change / last)``, is what the sweep after this
    one would move the angles by, the error of this one. Below ``tol`` it need not be run:
    a sweep fewer on most simulations, each as close to the fixed point as ``tol`` says.
    After the first change alone, the contraction of a similar solve (a fit's previous
    simulation), ``CONTRACTION_MARGIN`` times larger, stands in for the ratio.

    Args:
        change: Largest change of the angles in the last sweep, rad.
        last: The sweep before's (``inf`` if none).
        tol: The tolerance, rad.
        expected: A similar solve's contraction (NaN: none).
    """
    if change < tol:
        return True
    ratio = change / last if math.isfinite(last) else CONTRACTION_MARGIN * expected
    return ratio < CONTRACTION and change * ratio < tol


def _hold_drive(
    z0: np.ndarray, u: np.ndarray, h_phi1: np.ndarray, h_phi2: np.ndarray
) -> np.ndarray:
    """The first-order-hold increments of a modal forcing ``u``, with ``z0`` in row 0."""
    drive = np.empty_like(u)
    drive[0] = z0
    drive[1:] = (h_phi1 - h_phi2) * u[:-1] + h_phi2 * u[1:]
    return drive


def _free_response(drive: np.ndarray, e: np.ndarray) -> np.ndarray:
    """``z_k = e z_{k-1} + drive_k`` per mode (``z_0 = drive_0``): :func:`first_order_scan`."""
    return first_order_scan(drive.copy(), e)


#: A mode's ``e^step`` below this adds nothing the rounding keeps: the scan leaves it out.
NEGLIGIBLE_POWER = 1e-17


def first_order_scan(z: np.ndarray, e: np.ndarray) -> np.ndarray:
    """``z_k = e z_{k-1} + g_k`` (``z_0 = g_0``) for every column, by doubling, in place.

    ``z`` holds ``g`` on entry. After pass ``s``, ``z_k`` sums ``e^j g_{k-j}`` for
    ``j < 2^s`` (Hillis and Steele's parallel prefix, 1986): ``log2 N`` whole-array passes
    instead of N steps, as fast as ``scipy.signal.lfilter`` column by column and within
    1e-13 of it, without importing scipy.signal (about as long as a whole
    ``lumpbeam analyze``). Columns ordered by decreasing ``|e|`` let a pass leave out the
    trailing ones whose ``e^step`` is below :data:`NEGLIGIBLE_POWER` (modes that have died
    out); in another order every column is scanned.
    """
    power = np.asarray(e).copy()
    step = 1
    while step < z.shape[0]:
        alive = np.abs(power) > NEGLIGIBLE_POWER
        count = int(np.argmin(alive)) if not alive.all() else alive.size
        if alive[count:].any():
            count = alive.size
        if count == 0:
            break
        # The right-hand side is evaluated into a temporary first: the old z, as the scan needs.
        z[step:, :count] += power[:count] * z[:-step, :count]
        power = power * power
        step *= 2
    return z


def _friction_torque(rotation: float, compliance: float, torque: float) -> float:
    """The step's friction torque: holding (sticking) if within ``+-T``, else sliding."""
    holding = -rotation / compliance
    return holding if abs(holding) <= torque else float(-torque * np.sign(rotation))


def friction_steps_loop(
    drive: np.ndarray, e: np.ndarray, gamma: np.ndarray, angle_row: np.ndarray, torque: float
) -> np.ndarray:
    """The modal recurrence with dry friction at joint 1, one step at a time (the reference).

    Each step holds the friction torque ``f`` constant (its exact response is ``gamma f``,
    ``gamma = h phi1 b_1``) and decides it on the step's joint-1 rotation: the torque that
    keeps joint 1 still if it is within ``+-T`` (sticking), else ``-T`` against the rotation
    it would make (sliding). The work ``f * rotation`` is then never positive, so friction
    cannot pump energy into the stiff modes, whatever the step; deciding on the end-of-step
    rate, or smoothing the sign, does exactly that and chatters.

    Args:
        drive: Smooth-forcing increments per step, with the initial state in row 0, (T, m).
        e: ``e^{lam h}`` per mode.
        gamma: Modal response to a unit joint-1 torque held over one step.
        angle_row: Joint 1's angle as ``Re(angle_row . z)``.
        torque: Dry friction torque T, N m.

    Returns:
        Modal coordinates at the grid points, (T, m).
    """
    compliance = float((angle_row @ gamma).real)
    z = np.empty_like(drive)
    z[0] = current = drive[0]
    angle = float((angle_row @ current).real)
    for k in range(1, drive.shape[0]):
        free = e * current + drive[k]
        f = _friction_torque(float((angle_row @ free).real) - angle, compliance, torque)
        current = free + gamma * f
        angle = float((angle_row @ current).real)
        z[k] = current
    return z


_TABLES: dict[bytes, tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]] = {}

#: Rows of the stretch tables built first (:func:`_stretch_tables`): longer than most
#: stretches of a swing on the friction grid; a longer one extends them.
STRETCH_TABLE_ROWS = 512


def _stretch_tables(
    e: np.ndarray, gamma: np.ndarray, angle_row: np.ndarray, count: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """``e^m``, ``sum_{i<m} e^i`` and their joint-1 angles for ``m < count`` at least (cached).

    A fit simulates the same grid for the same chain in every sweep, so the tables are kept
    for the last few recurrences (keyed by their exact bytes). They are built only as long
    as asked: a stretch lasts about half a swing, far less than the grid.
    """
    key = e.tobytes() + gamma.tobytes() + angle_row.tobytes()
    tables = _TABLES.get(key)
    if tables is None or tables[0].shape[0] < count:
        powers = np.exp(np.log(e)[None, :] * np.arange(count)[:, None])
        sums = np.cumsum(np.vstack([np.zeros_like(e), powers[:-1]]), axis=0)
        tables = (powers, sums, powers * angle_row, (sums @ (angle_row * gamma)).real)
        if len(_TABLES) >= 8:
            _TABLES.pop(next(iter(_TABLES)))
        _TABLES[key] = tables
    return tables


def friction_steps(
    drive: np.ndarray, e: np.ndarray, gamma: np.ndarray, angle_row: np.ndarray, torque: float
) -> np.ndarray:
    """:func:`friction_steps_loop`, with each sliding stretch computed in one go.

    While joint 1 slides one way the torque is the constant ``c = -+T`` and the recurrence is
    linear: from a state ``z_s``, ``z_{s+m} = e^m (z_s - F_s) + F_{s+m} + gamma c sum_{i<m}
    e^i``, with ``F`` the friction-free response of the whole grid (one ``lfilter`` per mode).
    A stretch is extended (in windows that double) up to the first step whose decision is
    not "slide the same way"; that step, and every sticking step, is decided one at a time
    as in the reference. A drop test turns a few hundred times and sticks for a few steps at
    each turn, so the Python loop runs over those steps only. The result matches the
    reference to round-off (about 1e-16 rad of joint angle).

    Args:
        drive: See :func:`friction_steps_loop`.
        e: See :func:`friction_steps_loop`.
        gamma: See :func:`friction_steps_loop`.
        angle_row: See :func:`friction_steps_loop`.
        torque: See :func:`friction_steps_loop`.

    Returns:
        Modal coordinates at the grid points, (T, m).
    """
    count = drive.shape[0]
    compliance = float((angle_row @ gamma).real)
    free_response = _free_response(drive, e)
    free_angle = (free_response @ angle_row).real
    tables = _stretch_tables(e, gamma, angle_row, min(count, STRETCH_TABLE_ROWS))
    # A step decided alone: joint 1's angles by scalar arithmetic (Re(row . gamma f) is
    # compliance * f), the state by three vector operations: the Python loop runs over every
    # sticking step, so its cost per step is most of the solver's with friction.
    drive_angle = (drive @ angle_row).real.tolist()
    row_e = angle_row * e
    z = np.empty_like(drive)
    z[0] = current = drive[0]
    angle = float((angle_row @ current).real)
    k, window = 0, 32
    while k < count - 1:
        k += 1
        loose = float((row_e @ current).real) + drive_angle[k]  # joint 1 if frictionless
        rotation = loose - angle
        f = -rotation / compliance
        if abs(f) > torque:
            f = -torque if rotation > 0.0 else torque
        current = e * current + drive[k] + gamma * f
        z[k] = current
        angle = loose + compliance * f
        if abs(f) < torque or k == count - 1:
            continue  # sticking (the next step is decided alone too), or the grid's end
        delta = current - free_response[k]
        while True:
            end = min(count - 1, k + window)
            if end - k >= tables[0].shape[0]:
                tables = _stretch_tables(e, gamma, angle_row, min(count, 2 * (end - k) + 1))
            powers, sums, angle_powers, angle_sums = tables
            length = end - k  # steps m = 1 .. length ahead
            angles = (angle_powers[1 : length + 1] @ delta).real + free_angle[k + 1 : end + 1]
            angles += f * angle_sums[1 : length + 1]
            rotations = angles - compliance * f
            rotations[1:] -= angles[:-1]
            rotations[0] -= angle
            # Sliding on: a rotation beyond what the torque can hold, against the torque,
            # -f * rotation > torque * torque * compliance (|f| = torque, compliance > 0).
            bad = np.flatnonzero(-f * rotations <= torque * torque * compliance)
            if bad.size or end == count - 1:
                break
            window *= 2
        steps = int(bad[0]) if bad.size else length
        if steps:
            z[k + 1 : k + 1 + steps] = (
                powers[1 : steps + 1] * delta
                + free_response[k + 1 : k + 1 + steps]
                + f * gamma * sums[1 : steps + 1]
            )
            window = max(32, 2 * steps)
            k += steps
            current = z[k]
            angle = float((angle_row @ current).real)
    return z
