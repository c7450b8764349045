"""JointTrajectory messages to and from the core's joint motion (the one conversion)."""

import numpy as np
import pytest
import rclpy
from builtin_interfaces.msg import Duration, Time
from std_msgs.msg import Header
from trajectory_msgs.msg import JointTrajectory as JointTrajectoryMsg
from trajectory_msgs.msg import JointTrajectoryPoint

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.nodes.trajectory_messages import (
    MAX_MESSAGE_BYTES,
    MAX_POINTS,
    command_from_msg,
    command_subscription,
    trajectory_from_msg,
    trajectory_msg,
)


def _msg(names, points, stamp=None):
    return JointTrajectoryMsg(
        header=Header(stamp=stamp or Time()),
        joint_names=list(names),
        points=[
            JointTrajectoryPoint(positions=list(p), time_from_start=Duration(sec=s, nanosec=n))
            for (s, n), p in points
        ],
    )


def test_message_conversion_round_trips():
    trajectory = JointTrajectory(np.array([0.0, 0.5, 1.25]), np.array([[0.1], [0.2], [0.3]]))
    msg = trajectory_msg(trajectory, JointTrajectoryMsg())
    assert msg.points[2].time_from_start.sec == 1
    assert msg.points[2].time_from_start.nanosec == 250_000_000
    back = trajectory_from_msg(msg)
    assert np.array_equal(back.time_s, trajectory.time_s)
    assert np.array_equal(back.angles_rad, trajectory.angles_rad)


def test_a_command_keeps_its_stamp_and_a_single_point():
    # One point (go there by then) is a command for the arm simulator, not yet a trajectory.
    msg = _msg(['a', 'b'], [((2, 500_000_000), (0.1, -0.2))], Time(sec=7, nanosec=250_000_000))
    command = command_from_msg(msg)
    assert command.joint_names == ('a', 'b') and command.stamp_s == 7.25
    assert command.time_s.tolist() == [2.5]
    assert command.positions_rad.tolist() == [[0.1, -0.2]]
    with pytest.raises(LumpbeamError, match='at least 2 samples'):
        trajectory_from_msg(msg)


@pytest.mark.parametrize(
    ('names', 'points', 'problem'),
    [
        ([], [((0, 0), ())], 'no joint names'),
        (['a', 'b'], [((0, 0), (0.0, 0.0)), ((1, 0), (0.0,))], 'point 1 has 1 positions for 2'),
    ],
)
def test_a_malformed_message_is_one_clear_error(names, points, problem):
    with pytest.raises(LumpbeamError, match=problem):
        command_from_msg(_msg(names, points))


def test_a_command_of_too_many_points_is_refused():
    msg = _msg(['a'], [((0, 0), [0.0])])
    msg.points = msg.points * (MAX_POINTS + 1)
    with pytest.raises(LumpbeamError, match=f'{MAX_POINTS + 1} points, more than'):
        command_from_msg(msg)


def test_a_message_too_large_is_refused_before_it_is_deserialized(ros_graph):
    node = rclpy.create_node('commands', context=ros_graph.context)
    ros_graph.add_node(node)
    got, refused = [], []
    command_subscription(node, '/joint_trajectory', got.append, refused.append)
    huge = _msg(['a'], [((0, 0), [0.0])])
    huge.points[0].positions = np.zeros(MAX_MESSAGE_BYTES // 8 + 1).tolist()
    ros_graph.publish('/joint_trajectory', _msg(['a'], [((0, 0), [0.0]), ((1, 0), [1.0])]))
    ros_graph.wait_for_subscribers('/joint_trajectory')
    ros_graph.publish('/joint_trajectory', huge)
    ros_graph.publish('/joint_trajectory', _msg(['a'], [((0, 0), [0.0]), ((1, 0), [1.0])]))
    assert ros_graph.spin_until(lambda: refused and got, 30.0)
    assert refused[0].startswith('a message of 16.0 MiB, more than 16 MiB')
    assert got[-1].points[-1].positions.tolist() == [1.0]
