"""Residual vibration of each move in a record, and an unshaped move against a shaped one.

The live loop of the demo: an arm moves unshaped and rings, the identifier identifies its
modes, the shaper adopts them and the next move is shaped. Its figure of merit is the
residual vibration of each move (:mod:`lumpbeam_ros.core.model.arm.residual`: the RMS of the tip's
distance from its rest at the move's final angles, over the 3 s after the move ends), taken
here from what a record holds: the joint angles and the tip's positions.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import JOINT_STATES, TIP_POSE
from lumpbeam_ros.core.bagio import read_tip_poses
from lumpbeam_ros.core.bagio.series import read_joint_states
from lumpbeam_ros.core.ident.arm.moves import Move, find_moves
from lumpbeam_ros.core.model.arm.config import ArmConfig
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.residual import WINDOW_S, residual_rms, rest_tip


@dataclass(frozen=True)
class MoveResidual:
    """One move's residual vibration.

    Attributes:
        move: The move.
        residual_m: RMS distance of the tip from its rest over the window, m.
        rest: The tip's rest ``(x, z)`` at the move's final angles, m.
        t: Stamps in the window, s from the move's end.
        distance_m: The tip's distance from its rest at those stamps, m.
    """

    move: Move
    residual_m: float
    rest: tuple[float, float]
    t: np.ndarray
    distance_m: np.ndarray


def move_residuals(
    arm: ArmConfig,
    joint_t: np.ndarray,
    joint_q: np.ndarray,
    tip_t: np.ndarray,
    tip_x: np.ndarray,
    tip_z: np.ndarray,
    window_s: float = WINDOW_S,
) -> list[MoveResidual]:
    """The residual vibration of every move whose window the record covers.

    Args:
        arm: The arm (its rest positions).
        joint_t: Stamps of the joint angles, s.
        joint_q: Joint angles, rad, (len(joint_t), n_joints).
        tip_t: Stamps of the tip positions, s (evenly spaced).
        tip_x: Tip x, m.
        tip_z: Tip z, m.
        window_s: The window after each move, s.

    Returns:
        One entry per move, in time order.

    Raises:
        LumpbeamError: Angles for another arm, no move, or a move whose window the next
            move or the record's end cuts short.
    """
    model = ArmModel.from_config(arm)
    moves = find_moves(joint_t, joint_q)
    if not moves:
        raise LumpbeamError('residual vibration: the joints never move in the record')
    out = []
    tip_t = np.asarray(tip_t, dtype=float)
    for k, move in enumerate(moves):
        q = model.check_angles(move.final_rad, f'move {k + 1}: final joint angles')
        end = move.end_s + window_s
        if k + 1 < len(moves) and moves[k + 1].start_s < end:
            raise LumpbeamError(
                f'residual vibration: move {k + 2} starts {moves[k + 1].start_s:.3f} s, within '
                f'the {window_s:g} s after move {k + 1} ends ({move.end_s:.3f} s)'
            )
        rest = rest_tip(model, q)
        try:
            value = residual_rms(tip_t, tip_x, tip_z, rest, move.end_s, window_s)
        except LumpbeamError as exc:
            raise LumpbeamError(f'move {k + 1}: {exc}') from None
        inside = (tip_t >= move.end_s - 1e-9) & (tip_t <= end + 1e-9)
        distance = np.hypot(
            np.asarray(tip_x)[inside] - rest[0], np.asarray(tip_z)[inside] - rest[1]
        )
        out.append(MoveResidual(move, value, rest, tip_t[inside] - move.end_s, distance))
    return out


def bag_move_residuals(
    bag: str | Path,
    arm: ArmConfig,
    topic: str = TIP_POSE,
    window_s: float = WINDOW_S,
    joints_topic: str = JOINT_STATES,
) -> list[MoveResidual]:
    """:func:`move_residuals` of a recorded arm: a joint state topic and a tip pose topic.

    Raises:
        BagError: No such joint state topic or no such pose topic.
        LumpbeamError: As :func:`move_residuals`.
    """
    joints = read_joint_states(bag, joints_topic)
    poses = read_tip_poses(bag, topic)
    return move_residuals(arm, joints.t, joints.angles, poses.t, poses.x, poses.z, window_s)


@dataclass(frozen=True)
class ShapingOutcome:
    """An unshaped move against the shaped move that followed it.

    Attributes:
        unshaped: The unshaped move's residual.
        shaped: The shaped move's residual.
    """

    unshaped: MoveResidual
    shaped: MoveResidual

    @property
    def reduction(self) -> float:
        """``1 - shaped / unshaped``: the fraction of the residual vibration removed."""
        return 1.0 - self.shaped.residual_m / self.unshaped.residual_m

    def summary(self) -> str:
        """One line: both residuals and the reduction."""
        return (
            f'residual vibration: unshaped {1e3 * self.unshaped.residual_m:.3f} mm, shaped '
            f'{1e3 * self.shaped.residual_m:.3f} mm: {100 * self.reduction:.1f} % less'
        )
