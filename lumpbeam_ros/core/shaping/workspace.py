"""Each move of a trajectory shaped for the arm's own modes at its end (doc/arm.md).

An arm's modes change with its configuration, so one shaper cannot serve a whole workspace.
Here every move of a trajectory file (a stretch between rests, where every joint holds still)
gets the shaper designed for the first ``max_modes`` underdamped modes of the arm's model at
that move's final joint angles (B.16 linearized about the rest there,
:func:`~lumpbeam_ros.core.model.arm.statics.arm_modes`), and a later move starts later by the
time the shaping added before it.

A fast move through a large angle is not the linear, time-invariant system a textbook shaper
assumes (the inertia the springs carry turns while the move rings), so the exact modes of the
final configuration still leave part of the vibration. ``tune=True`` then adjusts each move's
impulses on the model's own simulation of that move (:mod:`lumpbeam_ros.core.shaping.tune`).

Each move's predicted residual is the model's: the RMS, over the 3 s after the move ends, of
the simulated tip's distance from its rest at the final angles
(:mod:`lumpbeam_ros.core.model.arm.residual`), with the move alone, from rest.

Example::

    shaper = WorkspaceShaper(arm, shaper='zvd', max_modes=2, tune=True)
    shaped, moves = shaper.shape(trajectory)
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.arm.moves import Move, find_moves
from lumpbeam_ros.core.model.arm.config import ArmConfig
from lumpbeam_ros.core.model.arm.drive import SampledMotion
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory, default_joint_names
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.residual import WINDOW_S, arm_residual
from lumpbeam_ros.core.model.arm.simulate import simulate_arm
from lumpbeam_ros.core.model.arm.statics import arm_modes
from lumpbeam_ros.core.shaping.apply import shape_trajectory, shaped_times
from lumpbeam_ros.core.shaping.choices import DEFAULT_MAX_MODES
from lumpbeam_ros.core.shaping.impulses import Impulses, Mode
from lumpbeam_ros.core.shaping.shapers import design_shaper

#: A rest in a trajectory file lasts at least this long, s: two rows at the same angles.
MIN_FILE_REST_S = 1e-9
#: Sample interval of the simulations that predict a move's residual, s.
PREDICTION_STEP_S = 2e-3


@dataclass(frozen=True)
class ShapedMove:
    """One move of a trajectory, shaped for its final configuration.

    Attributes:
        start_s: When the move leaves rest in the input, s.
        end_s: When it reaches its final angles in the input, s.
        final_q: The final joint angles, rad.
        modes: The model's modes there, shaped for.
        impulses: The shaper applied (tuned or not).
        predicted_residual_unshaped_m: The model's residual vibration of the move unshaped, m.
        predicted_residual_shaped_m: The same, shaped, m.
    """

    start_s: float
    end_s: float
    final_q: np.ndarray
    modes: tuple[Mode, ...]
    impulses: Impulses
    predicted_residual_unshaped_m: float
    predicted_residual_shaped_m: float

    @property
    def reduction(self) -> float:
        """``1 - shaped / unshaped``: the fraction of the predicted vibration removed."""
        if self.predicted_residual_unshaped_m == 0.0:
            return 0.0
        return 1.0 - self.predicted_residual_shaped_m / self.predicted_residual_unshaped_m

    def as_json(self) -> dict[str, Any]:
        """The entry of ``moves`` in ``lumpbeam shape --arm --json``."""
        return {
            'start_s': self.start_s,
            'end_s': self.end_s,
            'final_q': self.final_q.tolist(),
            'modes': [
                {'natural_frequency_hz': m.frequency_hz, 'damping_ratio': m.damping_ratio}
                for m in self.modes
            ],
            'impulses': self.impulses.as_list(),
            'duration_added_s': self.impulses.duration_s,
            'predicted_residual_unshaped_m': self.predicted_residual_unshaped_m,
            'predicted_residual_shaped_m': self.predicted_residual_shaped_m,
        }


def trajectory_moves(trajectory: JointTrajectory) -> tuple[Move, ...]:
    """The moves of a trajectory file: stretches between rows at which every joint holds.

    Args:
        trajectory: The trajectory.

    Returns:
        The moves in time order (none when the joints never move).
    """
    return find_moves(
        trajectory.time_s, trajectory.angles_rad, min_rest_s=MIN_FILE_REST_S, tolerance_rad=0.0
    )


def move_trajectory(trajectory: JointTrajectory, move: Move) -> JointTrajectory:
    """The rows of one move, from its last row at rest to its first at its final angles."""
    first = int(np.searchsorted(trajectory.time_s, move.start_s))
    last = int(np.searchsorted(trajectory.time_s, move.end_s))
    return JointTrajectory(
        trajectory.time_s[first : last + 1],
        trajectory.angles_rad[first : last + 1],
        trajectory.joint_names,
    )


def model_modes(model: ArmModel, q: np.ndarray, max_modes: int, what: str) -> tuple[Mode, ...]:
    """The first ``max_modes`` underdamped modes of the model at rest at ``q``.

    Raises:
        LumpbeamError: The arm has no underdamped mode there (or cannot stand there).
    """
    modes = arm_modes(model, q)
    count = min(max_modes, modes.natural_frequency_hz.size)
    if count == 0:
        raise LumpbeamError(f'{what}: the arm has no underdamped mode at its final angles')
    return tuple(
        Mode(float(modes.natural_frequency_hz[k]), float(modes.damping_ratio[k]))
        for k in range(count)
    )


def predicted_residual(model: ArmModel, move: JointTrajectory) -> float:
    """The model's residual vibration after a move alone, from rest at its first row, m."""
    end = float(move.time_s[-1])
    count = math.ceil((end + WINDOW_S - move.time_s[0]) / PREDICTION_STEP_S) + 1
    t = move.time_s[0] + PREDICTION_STEP_S * np.arange(count)
    motion = simulate_arm(model, SampledMotion(move), t)
    return arm_residual(model, motion, end)


class WorkspaceShaper:
    """Shapes each move of a trajectory for the arm's modes at its final angles.

    Args:
        arm: The arm's model (the identified arm file).
        shaper: ``'zv'``, ``'zvd'`` or ``'ei'``.
        max_modes: Modes shaped per move (the first, slowest ones).
        tune: Tune each move's impulses on the model's simulation of it.
        predict: Simulate each move to predict its residuals (the shaper node, which needs
            only the command, leaves them NaN when untuned).
    """

    def __init__(
        self,
        arm: ArmConfig,
        shaper: str = 'zvd',
        max_modes: int = DEFAULT_MAX_MODES,
        tune: bool = False,
        predict: bool = True,
    ):
        if max_modes < 1:
            raise LumpbeamError(f'max modes must be 1 or more, got {max_modes}')
        self.arm = arm
        self.model = ArmModel.from_config(arm)
        self.shaper = shaper
        self.max_modes = max_modes
        self.tune = tune
        self.predict = predict

    def shape(self, trajectory: JointTrajectory) -> tuple[JointTrajectory, list[ShapedMove]]:
        """Shapes every move of ``trajectory``.

        Args:
            trajectory: The commanded trajectory.

        Returns:
            The shaped trajectory (sampled as
            :func:`~lumpbeam_ros.core.shaping.apply.shaped_times` samples a shaped one) and
            each move's shaping, in time order.

        Raises:
            LumpbeamError: A trajectory for another number of joints or naming other joints
                than ``joint_1`` ... ``joint_n`` (in any order), angles outside a
                joint's limits, a move whose final configuration has no underdamped mode, or
                a shaped trajectory too long.
        """
        trajectory = self._in_joint_order(trajectory)
        self.arm.check_within_limits(trajectory.angles_rad, 'the trajectory')
        shaped_moves = [
            self.shape_move(move_trajectory(trajectory, move), k)
            for k, move in enumerate(trajectory_moves(trajectory), start=1)
        ]
        return assemble(trajectory, shaped_moves), shaped_moves

    def _in_joint_order(self, trajectory: JointTrajectory) -> JointTrajectory:
        """The trajectory's columns as the arm's joints, ``joint_1`` first (names any order).

        Raises:
            LumpbeamError: Another number of joints, or names that are not the arm's.
        """
        n = self.arm.n_joints
        if trajectory.joint_count != n:
            raise LumpbeamError(
                f'the trajectory has {trajectory.joint_count} joints, the arm {n} '
                f'({self.arm.source or "the arm file"})'
            )
        names = default_joint_names(n)
        given = trajectory.joint_names or names
        if given == names:
            return trajectory
        if sorted(given) != sorted(names):
            raise LumpbeamError(f'the trajectory names {list(given)}, the arm {list(names)}')
        order = [given.index(name) for name in names]
        return JointTrajectory(trajectory.time_s, trajectory.angles_rad[:, order], names)

    def shape_move(self, move: JointTrajectory, number: int = 1) -> ShapedMove:
        """Shapes one move (rest to rest) for the modes at its last row.

        Args:
            move: The move's rows.
            number: Its place in the trajectory, for messages.

        Returns:
            The move's shaping and its predicted residuals.
        """
        final = move.angles_rad[-1]
        modes = model_modes(self.model, final, self.max_modes, f'move {number}')
        impulses = design_shaper(self.shaper, modes)
        if not (self.predict or self.tune):
            return ShapedMove(
                float(move.time_s[0]),
                float(move.time_s[-1]),
                np.array(final),
                modes,
                impulses,
                math.nan,
                math.nan,
            )
        unshaped = predicted_residual(self.model, move)
        shaped = predicted_residual(self.model, shape_trajectory(move, impulses))
        if self.tune:
            from lumpbeam_ros.core.shaping.tune import tune_impulses

            tuned = tune_impulses(self.model, move, impulses, len(modes))
            residual = predicted_residual(self.model, shape_trajectory(move, tuned))
            if residual < shaped:
                impulses, shaped = tuned, residual
        return ShapedMove(
            start_s=float(move.time_s[0]),
            end_s=float(move.time_s[-1]),
            final_q=np.array(final),
            modes=modes,
            impulses=impulses,
            predicted_residual_unshaped_m=unshaped,
            predicted_residual_shaped_m=shaped,
        )


def assemble(trajectory: JointTrajectory, moves: list[ShapedMove]) -> JointTrajectory:
    """The trajectory with each move replaced by its shaped self, later moves delayed.

    A move's shaped rows are added as increments to the angles the previous moves left, so
    the rests between moves stay exactly at rest and last as long as they did.

    Args:
        trajectory: The input.
        moves: Its moves' shaping, in time order.

    Returns:
        The shaped trajectory, ``sum(duration_added_s)`` longer than the input.
    """
    added = sum(move.impulses.duration_s for move in moves)
    times = shaped_times(trajectory, added)
    angles = np.repeat(trajectory.angles_rad[:1], times.size, axis=0)
    delay = 0.0
    for move in moves:
        rows = move_trajectory(trajectory, Move(move.start_s, move.end_s, move.final_q))
        # sum_i A_i u(t - delay - t_i), each term the rows interpolated as the file is: exact
        # on any output grid, whatever the delay.
        lag = delay + move.impulses.time_s - move.impulses.time_s[0]
        for j in range(trajectory.joint_count):
            for t_i, a_i in zip(lag, move.impulses.amplitude, strict=True):
                angles[:, j] += a_i * (
                    np.interp(times - t_i, rows.time_s, rows.angles_rad[:, j])
                    - rows.angles_rad[0, j]
                )
        delay += move.impulses.duration_s
    if moves:
        # The sum of increments is the final angles only to round-off.
        angles[times >= moves[-1].end_s + delay - 1e-9] = trajectory.angles_rad[-1]
    return JointTrajectory(times, angles, trajectory.joint_names)
