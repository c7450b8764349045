"""The arm moved along a joint trajectory: B.16 with prescribed joint offsets, integrated.

The arm starts at rest in its static equilibrium at the motion's first angles and follows

    M(phi) phi'' + S(phi) phi'^2 + K phi + C phi' = g G cos phi + D^T (k o(q) + c o(q')),

(:class:`~lumpbeam_ros.core.model.chain.LumpedChain`, :mod:`lumpbeam_ros.core.model.arm.model`).

Two integrators. The default (``method='modal'``) follows the small deflections about the rigid
motion the joints prescribe (:mod:`lumpbeam_ros.core.model.arm.ltv`): the springs' linear part
exactly in modal coordinates, linearized afresh as the joints turn, the rest by waveform relaxation
on a 2 ms grid while the joints move and a 5 ms grid once they stop; it is many times faster than
integrating B.16 step by step (the bench's ``lsoda_s`` beside its time) and agrees with a tight
reference to a few hundredths of a micrometre (doc/arm.md, ``lumpbeam bench --only arm``). The
other (``method='lsoda'``, the reference, and the fallback when the deflections are too large for
the first) integrates B.16 in the angles and a momentum-like variable (:class:`_MomentumForm`) so
that the joint rates, which jump at every sample of a trajectory file, drop out of the right-hand
side, with ``scipy.integrate.solve_ivp(method='LSODA')`` and the Jacobian of the forces (springs,
gravity, dampers, the velocity terms; the change of ``M`` with ``phi`` in ``phi'`` left out, which
only slows its Newton iterations).

Either way, a trajectory of few samples (a few-row file's corners) is integrated sample to
sample, so no step straddles a corner; a dense one (smooth motion sampled at 1 kHz) is
followed through the cubic spline of its samples (:meth:`SampledMotion.spline`), whose rates
are continuous: stepping onto a thousand rate jumps a second costs an integrator 20 to 80 times
more than the motion itself.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.integrate import solve_ivp

from lumpbeam_ros.base.blas import single_threaded_blas
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model.arm.drive import JointMotion, SampledMotion
from lumpbeam_ros.core.model.arm.ltv import DeflectionSolver, RigidMotion
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.statics import arm_equilibrium
from lumpbeam_ros.core.model.hermite import hermite
from lumpbeam_ros.core.model.integrate import ChainState, ModalSolver
from lumpbeam_ros.core.model.modes import LinearModel

#: Restart the integration at every sample of a trajectory with at most this many samples in
#: the span (a few-row trajectory's corners); denser ones are integrated straight through.
MAX_RESTARTS = 200

#: The modal method's grid while the joints move, s, and its relaxation window in steps. On
#: the bench's three-link arm (a 2 s move) the tip is within 0.07 um of a tight reference at
#: 1 or 2 ms and 0.02 um at 0.5 ms; the first-order hold alone would give 0.23 um at 2 ms.
MOVE_STEP_S = 2e-3
MOVE_WINDOW = 128

#: The modal method's grid once the joints have stopped, s, and its window in steps: free
#: vibration about one configuration. 10 ms is enough for the bench's arm (0.04 um) but not
#: for the paper's beam as a one-link arm, whose faster modes the output's cubic Hermite
#: interpolation then misses by more than 0.1 urad.
HELD_STEP_S = 5e-3
HELD_WINDOW = 1024

#: Grid of the LSODA method's modal ring-down, s. The solver samples the nonlinear remainder with a
#: first-order hold, so its error falls as the step squared: at 0.5 ms a three-link arm's
#: ring-down agrees with integrating on to 0.1 um (1/180 s, the beam's grid, gives 8 um).
RING_DOWN_STEP_S = 5e-4


@dataclass(frozen=True)
class ArmMotion:
    """The arm on a time grid.

    Attributes:
        t: Times, s.
        q: Commanded joint angles, rad, (len(t), n_joints).
        phi: Segment angles, rad, (len(t), n).
        phi_dot: Segment rates, rad/s, (len(t), n).
        tip_x: x of the last link's free end in beam_base, m.
        tip_z: z of it, m.
        tip_pitch: Its pitch (the last segment's angle), rad.
        method: Which integrator produced it: ``'modal'`` or ``'lsoda'``.
    """

    t: np.ndarray
    q: np.ndarray
    phi: np.ndarray
    phi_dot: np.ndarray
    tip_x: np.ndarray
    tip_z: np.ndarray
    tip_pitch: np.ndarray
    method: str = 'modal'


class _MomentumForm:
    """B.16 in the angles and ``w = M(phi) phi' + C phi - B_c q``, with its Jacobian.

    ``w`` is the generalized momentum plus the dampers' stretch: with
    ``dT/dphi_i = -phi'_i sum_j A_ij sin(phi_i - phi_j) phi'_j`` (T the kinetic energy),

        phi' = M(phi)^-1 (w - C phi + B_c q),
        w'   = dT/dphi + g G cos phi - K phi + B_k q,

    where ``B_k q`` and ``B_c q`` are the springs' and dampers' prescribed stretches
    (``D^T k o(q)``, ``D^T c o(q)``). The joint rates ``q'`` have gone: a sampled trajectory's
    rates jump at every sample, its angles do not, so this right-hand side is continuous and
    an adaptive integrator does not stall on the samples.
    """

    def __init__(self, model: ArmModel, motion: JointMotion):
        chain = model.chain
        self.n = chain.n
        self.a = chain.inertia_coupling
        self.inertia = chain.inertia
        self.k = chain.stiffness_matrix
        self.c = chain.damping_matrix
        self.weight = chain.gravity * chain.gravity_moment
        self.motion = motion
        # B_k = D^T diag(k) E, E putting q_i on link i's first spring; B_c alike.
        unit = model.offsets(np.eye(model.n_joints))
        zero = np.zeros_like(unit)
        self.b_k = chain.drive_forces(unit, zero).T
        self.b_c = chain.drive_forces(zero, unit).T
        self.diag = np.diag_indices(self.n)

    def _drive(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        """``B_k q`` and ``B_c q`` at ``t``."""
        q = self.motion.angles(t)
        return self.b_k @ q, self.b_c @ q

    def rates(self, t: float, phi: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, ...]:
        """phi', and the pieces the Jacobian reuses: M, sin(phi_i - phi_j)."""
        spring, damper = self._drive(t)
        diff = phi[:, None] - phi[None, :]
        mass = self.a * np.cos(diff)
        mass[self.diag] += self.inertia
        phi_dot = np.linalg.solve(mass, w - self.c @ phi + damper)
        return phi_dot, mass, np.sin(diff), spring

    def state_from(self, t: float, phi: np.ndarray, phi_dot: np.ndarray) -> np.ndarray:
        """``[phi, w]`` from the angles and rates."""
        _, damper = self._drive(t)
        mass = self.a * np.cos(phi[:, None] - phi[None, :]) + np.diag(self.inertia)
        return np.concatenate([phi, mass @ phi_dot + self.c @ phi - damper])

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        """``[phi', w']``; NaN for a non-finite state.

        An adaptive integrator may try a step that overflows; the NaN it gets back makes it
        retry smaller, where evaluating the forces of a NaN state would only warn.
        """
        if not np.all(np.isfinite(y)):
            return np.full_like(y, np.nan)
        phi, w = y[: self.n], y[self.n :]
        phi_dot, _, sin, spring = self.rates(t, phi, w)
        d_t = -phi_dot * ((self.a * sin) @ phi_dot)
        w_dot = d_t + self.weight * np.cos(phi) - self.k @ phi + spring
        return np.concatenate([phi_dot, w_dot])

    def jacobian(self, t: float, y: np.ndarray) -> np.ndarray:
        """Of :meth:`rhs`, leaving out the change of ``M`` with ``phi`` in ``phi'``; NaN too."""
        if not np.all(np.isfinite(y)):
            return np.full((y.size, y.size), np.nan)
        phi, w = y[: self.n], y[self.n :]
        phi_dot, mass, sin, _ = self.rates(t, phi, w)
        m_inv = np.linalg.inv(mass)
        d_phidot_d_phi = -m_inv @ self.c
        as_ = self.a * sin
        # dT/dphi_i = -phi'_i sum_j A_ij s_ij phi'_j: its derivative in phi' ...
        d_t_d_phidot = -np.diag(as_ @ phi_dot) - phi_dot[:, None] * as_
        # ... and in phi at fixed phi' (ds_ij/dphi_i = c_ij, ds_ij/dphi_j = -c_ij).
        ac = self.a * np.cos(phi[:, None] - phi[None, :]) * phi_dot[None, :]
        d_t_d_phi = -phi_dot[:, None] * (np.diag(ac.sum(axis=1)) - ac)
        stiff = d_t_d_phi - self.k - np.diag(self.weight * np.sin(phi))
        top = np.hstack([d_phidot_d_phi, m_inv])
        bottom = np.hstack([stiff + d_t_d_phidot @ d_phidot_d_phi, d_t_d_phidot @ m_inv])
        return np.vstack([top, bottom])


def simulate_arm(
    model: ArmModel,
    motion: JointMotion,
    t_eval: np.ndarray,
    rtol: float = 1e-8,
    atol: float = 1e-10,
    modal_ring_down: bool = True,
    method: str = 'modal',
) -> ArmMotion:
    """Moves the arm along ``motion`` from rest, sampled at ``t_eval``.

    Args:
        model: The arm.
        motion: The joints' prescribed angles and rates.
        t_eval: Output times, increasing; the arm is at rest in its static equilibrium at
            ``motion.angles(t_eval[0])`` at the first.
        rtol: Relative tolerance of the LSODA method.
        atol: Its absolute tolerance, rad and rad/s.
        modal_ring_down: With the LSODA method, propagate the free vibration after the
            motion's end with the beam's modal solver
            (:class:`~lumpbeam_ros.core.model.integrate.ModalSolver`) instead of integrating on.
        method: ``'modal'`` (the deflections about the rigid motion,
            :mod:`lumpbeam_ros.core.model.arm.ltv`; falls back to LSODA when they are too large for
            it) or ``'lsoda'`` (B.16 integrated step by step, the reference).

    Returns:
        The motion at ``t_eval``.

    Raises:
        LumpbeamError: The motion has the wrong number of joints, the times do not increase,
            an unknown method, or the integrator failed.
    """
    t_eval = np.asarray(t_eval, dtype=float)
    if t_eval.ndim != 1 or t_eval.size == 0 or np.any(np.diff(t_eval) <= 0.0):
        raise LumpbeamError('arm simulation: output times must increase strictly')
    if motion.n_joints != model.n_joints:
        raise LumpbeamError(
            f'arm simulation: the arm has {model.n_joints} joints, the motion {motion.n_joints}'
        )
    if method not in ('modal', 'lsoda'):
        raise LumpbeamError(f'arm simulation: unknown method {method!r} (modal or lsoda)')
    t0, t1 = float(t_eval[0]), float(t_eval[-1])
    knots = motion.knots[(motion.knots > t0) & (motion.knots < t1)]
    drive = motion
    if knots.size > MAX_RESTARTS and isinstance(motion, SampledMotion):
        drive = motion.spline()
        knots = drive.knots[(drive.knots > t0) & (drive.knots < t1)]
    if method == 'modal':
        with single_threaded_blas():
            modal = _simulate_modal(model, drive, knots, t_eval)
        if modal is not None:
            phi, phi_dot = modal
            x, z, pitch = model.chain.tip_pose(phi)
            q = motion.sample(t_eval)[0]
            return ArmMotion(t_eval, q, phi, phi_dot, x, z, pitch)
    return _simulate_lsoda(model, motion, drive, knots, t_eval, rtol, atol, modal_ring_down)


def _simulate_modal(
    model: ArmModel, drive: JointMotion, knots: np.ndarray, t_eval: np.ndarray
) -> tuple[np.ndarray, np.ndarray] | None:
    """``(phi, phi_dot)`` at ``t_eval`` by :class:`~.ltv.DeflectionSolver`.

    The span is cut at the knots (where the rigid rates jump, the deflection rates jump the
    other way: ``phi'`` is continuous) and where the motion ends; each piece gets a uniform
    grid, fine while the joints move, coarse once they are held.

    Returns:
        ``None`` when the deflections are too large for the solver.
    """
    t0, t1 = float(t_eval[0]), float(t_eval[-1])
    end = min(max(t0, drive.end_time), t1)
    bounds = np.unique(np.concatenate([[t0], knots[knots < end], [end, t1]]))
    starts = model.link_starts

    def joint_angles(phi: np.ndarray) -> np.ndarray:
        return np.asarray(np.diff(phi, axis=-1, prepend=0.0)[..., starts])

    solver = DeflectionSolver(model.chain, joint_angles)
    q0 = drive.sample(np.array([t0]))[0][0]
    r0 = model.rigid_angles(q0)
    d = arm_equilibrium(model, q0) - r0
    grid_t, grid_phi, grid_rate = [np.array([t0])], [d + r0], [np.zeros_like(d)]
    for start, stop in zip(bounds[:-1], bounds[1:], strict=True):
        moving = start < end
        h_max, window = (MOVE_STEP_S, MOVE_WINDOW) if moving else (HELD_STEP_S, HELD_WINDOW)
        steps = max(1, int(np.ceil((stop - start) / h_max - 1e-9)))
        times = np.linspace(start, stop, steps + 1)
        # Rates and accelerations of the piece itself at its ends, not of its neighbours.
        inside = np.clip(times, start + 1e-9 * (stop - start), stop - 1e-9 * (stop - start))
        q, _, _ = drive.sample(times)
        _, q_dot, q_ddot = drive.sample(inside)
        rigid = RigidMotion(
            model.rigid_angles(q), model.rigid_angles(q_dot), model.rigid_angles(q_ddot)
        )
        # phi' carries over a knot (and is 0 at the start), so d' takes up the rigid rates'.
        d_dot = grid_rate[-1][-1] - rigid.r_dot[0]
        solved = solver.solve(d, d_dot, rigid, (stop - start) / steps, window)
        if solved is None:
            return None
        deflection, deflection_rate = solved
        grid_t.append(times[1:])
        grid_phi.append((rigid.r + deflection)[1:])
        grid_rate.append((rigid.r_dot + deflection_rate)[1:])
        d, d_dot = deflection[-1], deflection_rate[-1]
    t = np.concatenate(grid_t)
    if t.size < 2:
        return np.vstack(grid_phi), np.vstack(grid_rate)
    return hermite(t, np.vstack(grid_phi), np.vstack(grid_rate), t_eval)


def _simulate_lsoda(
    model: ArmModel,
    motion: JointMotion,
    drive: JointMotion,
    knots: np.ndarray,
    t_eval: np.ndarray,
    rtol: float,
    atol: float,
    modal_ring_down: bool,
) -> ArmMotion:
    """:func:`simulate_arm` by LSODA (and the modal ring-down when asked)."""
    n = model.chain.n
    t0, t1 = float(t_eval[0]), float(t_eval[-1])
    form = _MomentumForm(model, drive)
    y = form.state_from(t0, arm_equilibrium(model, drive.angles(t0)), np.zeros(n))
    # After the motion stops the arm rings down about one equilibrium: the modal solver's job.
    ring_start = max(t0, drive.end_time) if modal_ring_down else t1
    moving_end = min(t1, ring_start)
    knots = knots[knots < moving_end]
    bounds = [t0, *(knots if knots.size <= MAX_RESTARTS else []), moving_end]
    states = np.full((t_eval.size, 2 * n), np.nan)
    states[0] = y
    for start, end in zip(bounds[:-1], bounds[1:], strict=True):
        if end <= start:
            continue
        inside = (t_eval > start) & (t_eval <= end)
        wanted = t_eval[inside]
        if wanted.size == 0 or wanted[-1] != end:
            wanted = np.append(wanted, end)
        result = solve_ivp(
            form.rhs,
            (start, end),
            y,
            method='LSODA',
            t_eval=wanted,
            jac=form.jacobian,
            rtol=rtol,
            atol=atol,
        )
        if not result.success:
            raise LumpbeamError(f'arm simulation failed at t = {start:.3f} s: {result.message}')
        states[inside] = result.y.T[: int(inside.sum())]
        y = result.y[:, -1]
    phi = states[:, :n]
    tail = t_eval > ring_start
    phi_dot = np.full_like(phi, np.nan)
    phi_dot[~tail] = [
        form.rates(t, p, w)[0]
        for t, p, w in zip(t_eval[~tail], phi[~tail], states[~tail, n:], strict=True)
    ]
    if np.any(tail):
        start_state = ChainState(y[:n], form.rates(ring_start, y[:n], y[n:])[0])
        q_end = drive.angles(ring_start)
        rung = _ring_down(model, q_end, start_state, t_eval[tail] - ring_start)
        if rung is None:  # too large for the modal solver: integrate on
            result = solve_ivp(
                form.rhs,
                (ring_start, t1),
                y,
                method='LSODA',
                t_eval=t_eval[tail],
                jac=form.jacobian,
                rtol=rtol,
                atol=atol,
            )
            if not result.success:
                raise LumpbeamError(f'arm simulation failed after the move: {result.message}')
            tail_phi = result.y[:n].T
            tail_rates = [
                form.rates(t, p, w)[0]
                for t, p, w in zip(t_eval[tail], tail_phi, result.y[n:].T, strict=True)
            ]
            rung = tail_phi, np.array(tail_rates)
        phi[tail], phi_dot[tail] = rung
    x, z, pitch = model.chain.tip_pose(phi)
    return ArmMotion(t_eval, motion.sample(t_eval)[0], phi, phi_dot, x, z, pitch, 'lsoda')


def _ring_down(
    model: ArmModel, q: np.ndarray, state: ChainState, times: np.ndarray
) -> tuple[np.ndarray, np.ndarray] | None:
    """The free vibration with the joints held at ``q``, from ``state`` at time 0.

    The held joints make the spring offsets a constant preload on the beam's chain, whose
    modal solver then propagates the motion about the equilibrium on a uniform grid; the
    angles at ``times`` are the cubic Hermite interpolation of that grid.

    Returns:
        ``(phi, phi_dot)`` at ``times``, or ``None`` when the modal solver did not converge.
    """
    offsets = model.offsets(q)
    chain = replace(model.chain, preload=model.chain.drive_forces(offsets, 0.0 * offsets))
    linear = LinearModel.about_equilibrium(chain, arm_equilibrium(model, q))
    solution = ModalSolver(chain, linear).solve(state, float(times[-1]), RING_DOWN_STEP_S)
    if solution is None:
        return None
    return hermite(solution.t, solution.phi, solution.phi_dot, times)
