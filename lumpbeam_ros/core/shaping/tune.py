"""A move's impulses tuned on the arm model's simulation of that move (doc/arm.md).

A textbook shaper (ZV, ZVD, EI; Singer and Seering, Singhose) cancels the vibration of a
linear, time-invariant mode. A fast move through a large angle is neither: the inertia the
springs carry turns with the joints while the move excites them, so the shaper designed for
the exact modes of the final configuration still leaves part of the vibration (half of it on
the two-link arm's fast moves). The model knows the whole move, so the impulses are tuned on
its simulation instead (B.16 along the shaped command,
:func:`~lumpbeam_ros.core.model.arm.simulate.simulate_arm`):

* the unknowns are each impulse's amplitude (as a log factor on the untuned one, so every
  amplitude stays positive; they are normalised to sum to 1) and the time of every impulse
  but the first and the last (as a logit of its fraction of the untuned duration, so they
  stay between them): the shaped move ends exactly when the untuned one does;
* the misfit is the tip's deviation from its rest over the residual's window (the 3 s after
  the move ends, :mod:`lumpbeam_ros.core.model.arm.residual`) sampled every
  :data:`WINDOW_STEP_S`. After the move the joints hold and the remaining vibration is small,
  so the window is propagated from the simulated state at the move's end by the arm's
  linear model about that rest (:class:`RestWindow`) instead of simulated on;
* the solver is Levenberg-Marquardt whose Jacobian is taken once by forward differences (one
  simulation per unknown) and then kept up to date by Broyden's rank-one updates (one
  simulation per step), so a move costs a few tens of simulations of itself.

Example::

    tuned = tune_impulses(model, move, design_shaper('zvd', modes))
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model.arm.drive import SampledMotion
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.residual import WINDOW_S
from lumpbeam_ros.core.model.arm.simulate import simulate_arm
from lumpbeam_ros.core.model.arm.statics import arm_equilibrium, arm_linear_model
from lumpbeam_ros.core.shaping.apply import shape_trajectory
from lumpbeam_ros.core.shaping.impulses import Impulses

#: Sample interval of the window's deviations in the misfit, s.
WINDOW_STEP_S = 0.01
#: Simulations of the move a tuning may spend (the Jacobians' included).
MAX_SIMULATIONS = 160
#: The tuning stops once the window's RMS deviation falls below this fraction of the
#: unshaped move's.
GOOD_ENOUGH = 1e-3
#: Counts of evenly spaced equal impulses the tuning starts from after the untuned shaper.
_EVEN_STARTS = (3, 4)
#: Steps each start may take after its Jacobian before the next start is tried.
_PER_START = 12
#: Forward-difference step in the unknowns (log factors and logits).
_STEP = 1e-4
#: Largest step in any unknown (log factor or logit) at once.
_MAX_STEP = 1.0
#: The unknowns stay within +-_BOUND: amplitudes within a factor e^8 of the untuned ones.
_BOUND = 8.0
#: Steps in a row without progress after which the tuning stops.
_PATIENCE = 4


@dataclass(frozen=True)
class RestWindow:
    """The tip's deviations over the window, linear in the arm's state at a move's end.

    After the move the joints hold at ``q``: the vibration is free and small, so it follows
    B.16 linearized about the rest there, ``s' = A s`` with ``s = [phi - phi_eq, phi']``,
    and the tip's deviation is ``C (phi - phi_eq)`` (``C`` the tip position's derivative).

    Attributes:
        phi_eq: The rest's segment angles.
        operator: Maps ``s`` at the move's end to the stacked ``x`` then ``z`` deviations at
            the window's samples, shape (2 samples, 2 n).
        eigenvalues: Those of ``A``.
        vectors: Its eigenvectors (columns).
        coordinates: Their inverse: ``s`` to the eigen coordinates.
    """

    phi_eq: np.ndarray
    operator: np.ndarray
    eigenvalues: np.ndarray
    vectors: np.ndarray
    coordinates: np.ndarray

    @classmethod
    def at(cls, model: ArmModel, q: np.ndarray, window_s: float = WINDOW_S) -> RestWindow:
        """The window after a move ending at joint angles ``q``."""
        linear = arm_linear_model(model, q)
        phi_eq = arm_equilibrium(model, q)
        n = phi_eq.size
        position = np.empty((2, n))
        for j in range(n):
            step = np.zeros(n)
            step[j] = 1e-7
            x_up, z_up, _ = model.chain.tip_pose(phi_eq + step)
            x_down, z_down, _ = model.chain.tip_pose(phi_eq - step)
            position[:, j] = [(x_up - x_down) / 2e-7, (z_up - z_down) / 2e-7]
        eigenvalues, vectors = np.linalg.eig(linear.state_matrix())
        out = position @ vectors[:n]  # (2, 2n): the tip's share of each eigenvector
        coordinates = np.linalg.inv(vectors)  # s -> the eigen coordinates
        t = np.arange(0.0, window_s + 1e-9, WINDOW_STEP_S)
        growth = np.exp(np.outer(t, eigenvalues))  # (samples, 2n)
        rows = [np.real((out[axis] * growth) @ coordinates) for axis in range(2)]
        return cls(phi_eq, np.vstack(rows), eigenvalues, vectors, coordinates)

    def state(self, phi: np.ndarray, phi_dot: np.ndarray) -> np.ndarray:
        """``s = [phi - phi_eq, phi']``."""
        return np.concatenate([phi - self.phi_eq, phi_dot])

    def held(self, state: np.ndarray, elapsed_s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``e^(A t) s`` and ``A e^(A t) s`` for each ``t`` of ``elapsed_s`` (columns)."""
        modal = self.coordinates @ state
        growth = np.exp(np.outer(self.eigenvalues, elapsed_s)) * modal[:, None]
        return (
            np.real(self.vectors @ growth),
            np.real(self.vectors @ (self.eigenvalues[:, None] * growth)),
        )

    def deviations(self, phi: np.ndarray, phi_dot: np.ndarray) -> np.ndarray:
        """The tip's ``x`` then ``z`` deviations over the window from the state at its start, m."""
        return np.asarray(self.operator @ self.state(phi, phi_dot))

    @property
    def samples(self) -> int:
        """Samples in the window (of each coordinate)."""
        return int(self.operator.shape[0]) // 2


class _Parameters:
    """Impulses from the unknowns (see the module docstring), about the untuned ones."""

    def __init__(self, untuned: Impulses):
        self.untuned = untuned
        self.duration_s = untuned.duration_s
        inner = (untuned.time_s[1:-1] - untuned.time_s[0]) / self.duration_s
        inner = np.clip(inner, 1e-6, 1.0 - 1e-6)
        self._logits = np.log(inner / (1.0 - inner))
        self.size = inner.size + untuned.time_s.size

    def lti_jacobian(self, window: RestWindow, unshaped_end: np.ndarray) -> np.ndarray:
        """The misfit's Jacobian at the start, were the move linear and time-invariant.

        Then each delayed copy ``A_i u(t - t_i)`` of the move leaves at the shaped move's end
        ``A_i e^(A (T - t_i)) s_u``, ``s_u`` the unshaped move's state at its own end, and
        the misfit is ``R sum_i A_i e^(A (T - t_i)) s_u`` (``R`` the window's operator): its
        derivatives in the log amplitudes and the time logits are exact sums, no simulation.
        A fast move is not linear; Broyden's updates correct the difference step by step.
        """
        start = self.impulses(np.zeros(self.size))
        states, rates = window.held(unshaped_end, self.duration_s - start.time_s)
        copies, slopes = window.operator @ states, window.operator @ rates
        amplitude = start.amplitude
        linear = copies @ amplitude
        inner = self._logits.size
        jacobian = np.empty((linear.size, self.size))
        for k in range(1, inner + 1):
            t = start.time_s[k]
            # d t_k / d logit = t_k (1 - t_k / T); e^(A (T - t_k)) falls with t_k.
            jacobian[:, k - 1] = -amplitude[k] * slopes[:, k] * t * (1.0 - t / self.duration_s)
        jacobian[:, inner:] = amplitude * (copies - linear[:, None])
        return jacobian

    def impulses(self, x: np.ndarray) -> Impulses:
        inner = self._logits.size
        fractions = 1.0 / (1.0 + np.exp(-(self._logits + x[:inner])))
        times = np.concatenate([[0.0], self.duration_s * fractions, [self.duration_s]])
        amplitudes = self.untuned.amplitude * np.exp(x[inner:])
        order = np.argsort(times, kind='stable')
        return Impulses(times[order], amplitudes[order] / amplitudes.sum())


class _Misfit:
    """The window's deviations after the move shaped by given impulses; counts simulations."""

    def __init__(self, model: ArmModel, move: JointTrajectory, window: RestWindow):
        self.model = model
        self.move = move
        self.window = window
        self.simulations = 0
        self.end_state = np.zeros(0)

    def __call__(self, impulses: Impulses) -> np.ndarray:
        shaped = shape_trajectory(self.move, impulses)
        t = np.array([shaped.time_s[0], shaped.time_s[-1]])
        self.simulations += 1
        motion = simulate_arm(self.model, SampledMotion(shaped), t)
        self.end_state = self.window.state(motion.phi[-1], motion.phi_dot[-1])
        return np.asarray(self.window.operator @ self.end_state)


def _differences(
    misfit: _Misfit, parameters: _Parameters, x: np.ndarray, f: np.ndarray
) -> np.ndarray:
    """The misfit's Jacobian at ``x`` by forward differences: one simulation per unknown."""
    jacobian = np.empty((f.size, x.size))
    for i in range(x.size):
        step = x.copy()
        step[i] += _STEP
        jacobian[:, i] = (misfit(parameters.impulses(step)) - f) / _STEP
    return jacobian


def _descend(
    misfit: _Misfit,
    parameters: _Parameters,
    target: float,
    limit: int,
    start: tuple[np.ndarray, np.ndarray] | None = None,
    jacobian: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Levenberg-Marquardt in ``parameters``' unknowns, Broyden's Jacobian.

    Args:
        misfit: The misfit (counts the simulations).
        parameters: The unknowns about a starting shaper.
        target: Squared misfit at which to stop.
        limit: Simulations (counted by ``misfit``) after which to stop.
        start: The unknowns to start from and their misfit (default: the starting shaper).
        jacobian: A first Jacobian to start from (default: by differences); when it stops
            helping, one by differences replaces it.

    Returns:
        The unknowns reached and their misfit.
    """
    if start is None:
        x = np.zeros(parameters.size)
        f = misfit(parameters.impulses(x))
    else:
        x, f = start
    if jacobian is None:
        stalled, fresh = _PATIENCE, False
        jacobian = np.zeros((f.size, x.size))
        damping = 0.0
    else:
        stalled, fresh = 0, False
        jacobian = jacobian.copy()
        damping = 1e-3 * float(np.max(np.diag(jacobian.T @ jacobian)))
    while misfit.simulations < limit and float(f @ f) > target:
        if stalled >= _PATIENCE:
            # Broyden's Jacobian has drifted, or the last fresh one has run out of steps.
            if fresh or misfit.simulations + x.size >= limit:
                break
            jacobian = _differences(misfit, parameters, x, f)
            damping = 1e-3 * float(np.max(np.diag(jacobian.T @ jacobian)))
            stalled, fresh = 0, True
            continue
        normal = jacobian.T @ jacobian
        scale = np.diag(np.diag(normal)) + 1e-12 * np.eye(x.size)
        try:
            dx = -np.linalg.solve(normal + damping * scale, jacobian.T @ f)
        except np.linalg.LinAlgError:
            dx = np.full_like(x, np.nan)
        if not np.all(np.isfinite(dx)):
            damping *= 4.0
            stalled += 1
            continue
        # A step of at most _MAX_STEP in any unknown, within the box of _BOUND.
        dx *= min(1.0, _MAX_STEP / max(float(np.max(np.abs(dx))), 1e-300))
        dx = np.clip(x + dx, -_BOUND, _BOUND) - x
        if not np.any(dx):
            break
        try:
            trial = misfit(parameters.impulses(x + dx))
        except LumpbeamError:
            damping *= 4.0
            stalled += 1
            continue
        # Broyden: the Jacobian made to map this step to the change it caused.
        jacobian += np.outer(trial - f - jacobian @ dx, dx) / float(dx @ dx)
        if float(trial @ trial) < float(f @ f):
            x, f = x + dx, trial
            damping /= 3.0
            stalled, fresh = 0, False
        else:
            damping *= 4.0
            stalled += 1
    return x, f


def starts(untuned: Impulses, modes: int) -> list[Impulses]:
    """Where the tuning starts: the untuned shaper, then shapers of few impulses.

    A shaper of many impulses (two modes' ZVD convolved: nine) has many local minima on a
    move far from linear; shapers of three to four impulses spread over the same time have
    few unknowns and often reach what the untuned start cannot (the tapered two-link arm's
    elbow through 2.6 rad in 0.6 s: 0.93 of the unshaped residual from ZVD, 0.018 to 0.026
    from them). Each is stretched to end when the untuned shaper does.

    Args:
        untuned: The untuned shaper.
        modes: How many modes it was designed for (its impulses beyond the first mode's
            three are the other modes' shapers convolved in).
    """
    duration = untuned.duration_s
    out = [untuned]
    for count in _EVEN_STARTS:
        out.append(Impulses(np.linspace(0.0, duration, count), np.full(count, 1.0 / count)))
    if modes > 1:
        # The slowest mode's own three impulses (ZVD's 1 : 2K : K^2 with K near 1).
        out.append(Impulses(np.array([0.0, 0.5, 1.0]) * duration, np.array([0.25, 0.5, 0.25])))
    return out


def tune_impulses(
    model: ArmModel,
    move: JointTrajectory,
    untuned: Impulses,
    modes: int = 1,
    max_simulations: int = MAX_SIMULATIONS,
) -> Impulses:
    """Tunes a move's impulses so that the model's residual vibration after it is smallest.

    Each start of :func:`starts` gets a short descent (its Jacobian and
    :data:`_PER_START` steps) until one leaves less than :data:`GOOD_ENOUGH` of the unshaped
    move's misfit; the best then descends on with the simulations left.

    Args:
        model: The arm.
        move: The move, rest to rest (its rows; held before the first and after the last).
        untuned: The shaper designed for the modes at its final angles: the first start, and
            the bound on the duration (the tuned impulses end when these do).
        modes: How many modes ``untuned`` was designed for.
        max_simulations: Simulations of the move the tuning may spend.

    Returns:
        The tuned impulses (amplitudes positive, summing to 1, the last at the untuned
        last's time); the untuned ones when they are a single impulse (nothing to tune).

    Raises:
        LumpbeamError: The move cannot be simulated.
    """
    if untuned.time_s.size < 2:
        return untuned
    misfit = _Misfit(model, move, RestWindow.at(model, move.angles_rad[-1]))
    unshaped = misfit(Impulses(np.zeros(1), np.ones(1)))
    unshaped_end = misfit.end_state
    target = GOOD_ENOUGH**2 * float(unshaped @ unshaped)
    # Each start gets a short descent; the best then gets what is left.
    best: tuple[_Parameters, np.ndarray, np.ndarray] | None = None
    for start in starts(untuned, modes):
        parameters = _Parameters(start)
        limit = min(max_simulations, misfit.simulations + parameters.size + _PER_START)
        first = parameters.lti_jacobian(misfit.window, unshaped_end)
        x, f = _descend(misfit, parameters, target, limit, jacobian=first)
        if best is None or float(f @ f) < float(best[2] @ best[2]):
            best = parameters, x, f
        if float(f @ f) <= target or misfit.simulations >= max_simulations:
            break
    assert best is not None
    parameters, x, f = best
    if float(f @ f) > target and misfit.simulations < max_simulations:
        x, f = _descend(misfit, parameters, target, max_simulations, start=(x, f))
    return parameters.impulses(x)
