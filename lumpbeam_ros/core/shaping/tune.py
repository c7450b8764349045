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

import math
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
#: Simulations of the move a tuning may spend (the Jacobian's included).
MAX_SIMULATIONS = 40
#: The tuning stops once the window's RMS deviation falls below this fraction of the
#: untuned shaper's.
GOOD_ENOUGH = 1e-3
#: Forward-difference step in the unknowns (log factors and logits).
_STEP = 1e-4
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
    """

    phi_eq: np.ndarray
    operator: np.ndarray

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
        return cls(phi_eq, np.vstack(rows))

    def deviations(self, phi: np.ndarray, phi_dot: np.ndarray) -> np.ndarray:
        """The tip's ``x`` then ``z`` deviations over the window from the state at its start, m."""
        return np.asarray(self.operator @ np.concatenate([phi - self.phi_eq, phi_dot]))

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

    def __call__(self, impulses: Impulses) -> np.ndarray:
        shaped = shape_trajectory(self.move, impulses)
        t = np.array([shaped.time_s[0], shaped.time_s[-1]])
        self.simulations += 1
        motion = simulate_arm(self.model, SampledMotion(shaped), t)
        return self.window.deviations(motion.phi[-1], motion.phi_dot[-1])


def tune_impulses(
    model: ArmModel,
    move: JointTrajectory,
    untuned: Impulses,
    max_simulations: int = MAX_SIMULATIONS,
) -> Impulses:
    """Tunes a move's impulses so that the model's residual vibration after it is smallest.

    Args:
        model: The arm.
        move: The move, rest to rest (its rows; held before the first and after the last).
        untuned: The shaper designed for the modes at its final angles: the start, and the
            bound on the duration (the tuned impulses end when these do).
        max_simulations: Simulations of the move the tuning may spend.

    Returns:
        The tuned impulses (amplitudes positive, summing to 1, the last at the untuned
        last's time); the untuned ones when the move has no unknown to tune.

    Raises:
        LumpbeamError: The untuned shaped move cannot be simulated.
    """
    parameters = _Parameters(untuned)
    if untuned.time_s.size < 2:
        return untuned
    misfit = _Misfit(model, move, RestWindow.at(model, move.angles_rad[-1]))
    x = np.zeros(parameters.size)
    f = misfit(untuned)
    good_enough = GOOD_ENOUGH**2 * float(f @ f)
    jacobian = np.empty((f.size, x.size))
    for i in range(x.size):
        step = np.zeros_like(x)
        step[i] = _STEP
        jacobian[:, i] = (misfit(parameters.impulses(step)) - f) / _STEP
    normal = jacobian.T @ jacobian
    damping = 1e-3 * float(np.max(np.diag(normal)))
    stalled = 0
    while misfit.simulations < max_simulations and float(f @ f) > good_enough:
        normal = jacobian.T @ jacobian
        scale = np.diag(np.diag(normal)) + 1e-12 * np.eye(x.size)
        dx = -np.linalg.solve(normal + damping * scale, jacobian.T @ f)
        try:
            trial = misfit(parameters.impulses(x + dx))
        except LumpbeamError:
            damping *= 4.0
            stalled += 1
        else:
            # Broyden: the Jacobian made to map this step to the change it caused.
            jacobian += np.outer(trial - f - jacobian @ dx, dx) / float(dx @ dx)
            if float(trial @ trial) < float(f @ f):
                x, f = x + dx, trial
                damping /= 3.0
                stalled = 0
            else:
                damping *= 4.0
                stalled += 1
        if stalled >= _PATIENCE or not math.isfinite(damping):
            break
    return parameters.impulses(x)
