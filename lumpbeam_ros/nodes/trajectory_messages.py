"""``trajectory_msgs/JointTrajectory`` to and from the core's joint motion: the one conversion.

The shaper node, the arm simulator node and the demo's arm loop read commands here and write
them here, so a command means the same to each: positions only, each point's
``time_from_start`` in whole nanoseconds, the header's stamp as the command's start.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from builtin_interfaces.msg import Duration
from rclpy.node import Node
from rclpy.serialization import deserialize_message
from rclpy.subscription import Subscription
from trajectory_msgs.msg import JointTrajectory as JointTrajectoryMsg
from trajectory_msgs.msg import JointTrajectoryPoint

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.bagio.convert import NS_PER_S, time_ns
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.nodes.endpoints import subscription

#: Most points a command may hold (100 s of 1 kHz samples) ...
MAX_POINTS = 100_000
#: ... and most bytes its message may take, checked before it is deserialized: rclpy spends
#: seconds and a gigabyte turning a million points into Python objects.
MAX_MESSAGE_BYTES = 16 * 2**20


@dataclass(frozen=True)
class JointCommand:
    """A JointTrajectory message's content, as received (no point count or order checked).

    Attributes:
        joint_names: The joints, in the order of each point's positions.
        time_s: Each point's ``time_from_start``, s.
        positions_rad: Angles, rad, (points, joints).
        stamp_s: The header's stamp, s (0: start when received).
    """

    joint_names: tuple[str, ...]
    time_s: np.ndarray
    positions_rad: np.ndarray
    stamp_s: float


def command_from_msg(msg: JointTrajectoryMsg) -> JointCommand:
    """The positions of a JointTrajectory message against ``time_from_start``.

    Raises:
        LumpbeamError: No joint names, more than :data:`MAX_POINTS` points, or a point without
            one position per joint.
    """
    names = tuple(msg.joint_names)
    if not names:
        raise LumpbeamError('no joint names')
    if len(msg.points) > MAX_POINTS:
        raise LumpbeamError(f'{len(msg.points)} points, more than {MAX_POINTS}')
    for i, point in enumerate(msg.points):
        if len(point.positions) != len(names):
            raise LumpbeamError(
                f'point {i} has {len(point.positions)} positions for {len(names)} joints'
            )
    time = np.array([time_ns(p.time_from_start) for p in msg.points], dtype=float) / NS_PER_S
    angles = np.array([list(p.positions) for p in msg.points], dtype=float)
    return JointCommand(
        names, time, angles.reshape(time.size, len(names)), time_ns(msg.header.stamp) / NS_PER_S
    )


def trajectory_from_msg(msg: JointTrajectoryMsg) -> JointTrajectory:
    """A JointTrajectory message as the core's joint trajectory (times from its start).

    Raises:
        LumpbeamError: What :func:`command_from_msg` or
            :class:`~lumpbeam_ros.core.model.arm.joint_trajectory.JointTrajectory` refuses.
    """
    command = command_from_msg(msg)
    return JointTrajectory(command.time_s, command.positions_rad, command.joint_names)


def trajectory_msg(trajectory: JointTrajectory, like: JointTrajectoryMsg) -> JointTrajectoryMsg:
    """A JointTrajectory message of positions, with the header of ``like``."""
    msg = JointTrajectoryMsg(header=like.header, joint_names=list(trajectory.joint_names))
    nanoseconds = np.rint(trajectory.time_s * NS_PER_S).astype(np.int64)
    seconds, remainder = np.divmod(nanoseconds, NS_PER_S)
    msg.points = [
        JointTrajectoryPoint(
            positions=row.tolist(), time_from_start=Duration(sec=int(s), nanosec=int(r))
        )
        for row, s, r in zip(trajectory.angles_rad, seconds, remainder, strict=True)
    ]
    return msg


def command_subscription(
    node: Node,
    topic: str,
    on_command: Callable[[JointTrajectoryMsg], None],
    on_refused: Callable[[str], None],
) -> Subscription:
    """Subscribes to commands, refusing one over :data:`MAX_MESSAGE_BYTES` undeserialized.

    Args:
        node: The subscribing node.
        topic: The commands' topic.
        on_command: Called with each command of a bounded size.
        on_refused: Called with the reason for each command refused.

    Returns:
        The subscription (of serialized messages).
    """

    def on_bytes(raw: bytes) -> None:
        if len(raw) > MAX_MESSAGE_BYTES:
            on_refused(
                f'a message of {len(raw) / 2**20:.1f} MiB, more than '
                f'{MAX_MESSAGE_BYTES / 2**20:.0f} MiB'
            )
            return
        on_command(deserialize_message(raw, JointTrajectoryMsg))

    return subscription(node, JointTrajectoryMsg, topic, on_bytes, raw=True)
