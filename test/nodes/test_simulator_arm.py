"""The simulator node's arm mode on the real middleware: against the offline simulation."""

import numpy as np
import pytest
import yaml
from builtin_interfaces.msg import Duration
from geometry_msgs.msg import PoseStamped
from harness import arm_status_msg
from rclpy.parameter import Parameter
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectory as JointTrajectoryMsg
from trajectory_msgs.msg import JointTrajectoryPoint
from visualization_msgs.msg import MarkerArray

from lumpbeam_ros.base.interface import ARM_PARAMS
from lumpbeam_ros.core.bagio.convert import quaternion_to_pitch
from lumpbeam_ros.core.ident.arm.link_fit import scaled_arm
from lumpbeam_ros.core.model.arm.config import load_arm_config
from lumpbeam_ros.core.model.arm.drive import SampledMotion
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.simulate import simulate_arm
from lumpbeam_ros.core.model.arm.statics import arm_modes
from lumpbeam_ros.nodes.msgtypes import topic_qos
from lumpbeam_ros.nodes.simulator_node import SimulatorNode

#: A light two-link arm (7 segments): quick to simulate.
ARM = {
    'arm': {
        'plane': 'vertical',
        'payload_kg': 0.3,
        'links': [
            {'length_m': 1.0, 'n_segments': 4, 'ei_nm2': 500.0, 'mass_kg': 1.0,
             'damping_beta': 1e-3},
            {'length_m': 0.7, 'n_segments': 3, 'ei_nm2': [400.0, 300.0, 200.0],
             'mass_kg': 0.5, 'damping_beta': 1.5e-3, 'joint_mass_kg': 0.8},
        ],
    }
}  # fmt: skip
START_S = 100.0
RATE_HZ = 100.0


@pytest.fixture(scope='module')
def arm_file(tmp_path_factory):
    path = tmp_path_factory.mktemp('arm') / 'arm.yaml'
    path.write_text(yaml.safe_dump(ARM))
    return path


def _start(ros_graph, arm_file, **overrides):
    values = {
        'arm_config': str(arm_file),
        'use_sim_time': True,
        'rate_hz': RATE_HZ,
        'arm_ring_down_s': 1.0,
        **overrides,
    }
    params = [Parameter(name, value=value) for name, value in values.items()]
    node = SimulatorNode(context=ros_graph.context, parameter_overrides=params)
    ros_graph.add_node(node)
    return node


def _move(duration=0.3, step=0.005):
    t = np.arange(0.0, duration + 1e-9, step)
    s = t / duration
    return t, np.outer(s - np.sin(2 * np.pi * s) / (2 * np.pi), [0.4, -0.5])


def _command(names, times, positions):
    msg = JointTrajectoryMsg(joint_names=list(names))
    for t, row in zip(times, positions, strict=True):
        sec, nanosec = divmod(round(t * 1e9), 1_000_000_000)
        msg.points.append(
            JointTrajectoryPoint(
                positions=[float(v) for v in row],
                time_from_start=Duration(sec=sec, nanosec=nanosec),
            )
        )
    return msg


def _send(ros_graph, topic, msg):
    ros_graph.publish(topic, msg)  # creates the publisher (this one may be lost) ...
    assert ros_graph.wait_for_subscribers(topic)
    ros_graph.publish(topic, msg)  # ... this one arrives


def _stamps(messages):
    return np.array([m.header.stamp.sec + 1e-9 * m.header.stamp.nanosec for m in messages])


def test_follows_a_command_as_the_offline_simulation_under_sim_time(ros_graph, arm_file):
    poses = ros_graph.collect('/tip_pose_predicted', PoseStamped, 400)
    joints = ros_graph.collect('/joint_states', JointState, 400)
    markers = ros_graph.collect('/beam_markers', MarkerArray, 50)
    node = _start(ros_graph, arm_file, arm_commands='/joint_trajectory_shaped')
    ros_graph.set_clock([node], START_S)
    t, q = _move()
    # Named in another order than the arm's: the node reorders by name. The first send may
    # be lost before discovery; the second must then start where the first would have.
    msg = _command(['joint_2', 'joint_1'], t, q[:, ::-1])
    _send(ros_graph, '/joint_trajectory_shaped', msg)
    assert ros_graph.spin_until(lambda: node.arm.accepted >= 1, 10.0)
    assert node.arm.stream.anchor_s == START_S
    for step in range(1, 61):  # 0.6 s of /clock at 100 Hz
        ros_graph.set_clock([node], START_S + step / RATE_HZ)
    assert ros_graph.spin_until(lambda: len(poses) >= 61 and len(joints) >= 61, 10.0)
    ros_graph.spin_for(0.3)
    stamps = _stamps(poses)
    np.testing.assert_allclose(stamps, START_S + np.arange(61) / RATE_HZ, atol=1e-6)
    np.testing.assert_array_equal(_stamps(joints), stamps)
    assert list(joints[0].name) == ['joint_1', 'joint_2']
    model = ArmModel.from_config(load_arm_config(arm_file))
    # The node simulates in seconds from the anchor, the command's times as the message
    # carries them (whole nanoseconds): the modal method moves by a few tenths of a
    # micrometre when they move by their rounding.
    times = np.round(t * 1e9) / 1e9
    offline = simulate_arm(model, SampledMotion(JointTrajectory(times, q)), stamps - START_S)
    got_q = np.array([m.position for m in joints])
    got_x = np.array([p.pose.position.x for p in poses])
    got_z = np.array([p.pose.position.z for p in poses])
    orientation = [p.pose.orientation for p in poses]
    got_pitch = np.array([quaternion_to_pitch(o.x, o.y, o.z, o.w) for o in orientation])
    difference = np.hypot(got_x - offline.tip_x, got_z - offline.tip_z)
    pitch_error = np.abs(got_pitch - offline.tip_pitch).max()
    print(
        f'\nnode vs offline, {stamps.size} samples over {np.ptp(stamps):.2f} s, tip travel '
        f'{np.ptp(offline.tip_x):.3f} m: position RMS {np.sqrt(np.mean(difference**2)):.3g} m, '
        f'max {difference.max():.3g} m; pitch max {pitch_error:.3g} rad;'
        f' joint angles max {np.abs(got_q - offline.q).max():.3g} rad'
    )
    np.testing.assert_allclose(got_q, offline.q, atol=1e-12)
    assert difference.max() < 1e-6
    assert np.abs(got_pitch - offline.tip_pitch).max() < 1e-6
    assert np.ptp(offline.tip_x) > 0.1  # it moved
    # The whole arm on /beam_markers: a strip per link, joined at joint 2.
    assert ros_graph.spin_until(lambda: len(markers) > 0, 5.0)
    links = [m for m in markers[-1].markers if m.ns == 'arm_link']
    assert [m.id for m in links] == [0, 1] and [len(m.points) for m in links] == [5, 4]
    assert links[0].points[-1] == links[1].points[0]
    # A replayed bag that loops: the clock goes back and the arm restarts at rest, at the
    # angles the joints had then (before the command: its first point).
    before = len(poses)
    ros_graph.set_clock([node], 50.0)
    assert ros_graph.spin_until(lambda: len(poses) > before, 10.0)
    for step in range(1, 6):
        ros_graph.set_clock([node], 50.0 + step / RATE_HZ)
    assert ros_graph.spin_until(lambda: len(poses) >= before + 6, 10.0)
    again = poses[before:]
    np.testing.assert_allclose(_stamps(again)[:6], 50.0 + np.arange(6) / RATE_HZ, atol=1e-6)
    assert np.ptp([p.pose.position.z for p in again]) < 1e-9
    assert ros_graph.spin_until(lambda: _stamps(joints[-1:])[0] >= 50.05, 5.0)
    np.testing.assert_allclose(joints[-1].position, q[0], atol=1e-12)


def test_the_identified_arm_is_adopted_only_when_asked_and_valid(ros_graph, arm_file):
    nominal = load_arm_config(arm_file)
    identified = scaled_arm(nominal, np.array([1.3, 0.7]), np.array([2e-3, 1e-3]))
    latched = topic_qos(ARM_PARAMS)
    idle = _start(ros_graph, arm_file)
    node = _start(ros_graph, arm_file, adopt_identified=True)
    for bad in (
        arm_status_msg(identified, level=1),
        arm_status_msg(identified, link_1_damping_beta=float('nan')),
        arm_status_msg(identified, link_2_k_total_nm_per_rad_std=1e9),
    ):
        ros_graph.publish(ARM_PARAMS, bad, latched)
        ros_graph.spin_for(0.3)
    assert node.arm.adopted == 0
    ros_graph.publish(ARM_PARAMS, arm_status_msg(identified), latched)
    assert ros_graph.spin_until(lambda: node.arm.adopted == 1, 10.0)
    ros_graph.spin_for(0.3)
    assert idle.arm.adopted == 0
    # The stream simulates the identified arm from now on: its modes, not the file's.
    q = np.array([0.2, -0.3])
    want = arm_modes(ArmModel.from_config(identified), q).natural_frequency_hz
    got = arm_modes(node.arm.stream.model, q).natural_frequency_hz
    assert got[:2] == pytest.approx(want[:2], rel=1e-6)
    kept = arm_modes(idle.arm.stream.model, q).natural_frequency_hz
    assert kept[0] != pytest.approx(want[0], rel=1e-3)
