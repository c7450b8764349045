"""The shaper node on a private graph: fixed and live modes, invalid estimates, bad input."""

import math

import numpy as np
import pytest
from arm_cases import minimum_jerk, small_arm
from builtin_interfaces.msg import Duration
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from harness import arm_status_msg
from trajectory_msgs.msg import JointTrajectory as JointTrajectoryMsg
from trajectory_msgs.msg import JointTrajectoryPoint

from lumpbeam_ros.base.errors import ConfigError, LumpbeamError
from lumpbeam_ros.base.interface import ARM_PARAMS, BEAM_PARAMS, IDENTIFIER_STATUS
from lumpbeam_ros.base.interface import JOINT_TRAJECTORY as IN
from lumpbeam_ros.base.interface import JOINT_TRAJECTORY_SHAPED as OUT
from lumpbeam_ros.core.ident.arm.learner import arm_from_status
from lumpbeam_ros.core.ident.arm.link_fit import scaled_arm
from lumpbeam_ros.core.model.arm.config import load_arm_config, write_arm_config
from lumpbeam_ros.core.shaping.apply import shape_trajectory
from lumpbeam_ros.core.shaping.impulses import Mode
from lumpbeam_ros.core.shaping.shapers import design_shaper
from lumpbeam_ros.core.shaping.workspace import WorkspaceShaper
from lumpbeam_ros.nodes.msgtypes import topic_qos
from lumpbeam_ros.nodes.shaper_node import ShaperNode
from lumpbeam_ros.nodes.trajectory_messages import trajectory_from_msg

OK, ERROR = 0, 2
TRUTH = small_arm(2)
NOMINAL = scaled_arm(TRUTH, np.array([0.8, 1.2]), np.array([1.3e-3, 1.2e-3]))


def _command(times=(0.0, 0.1, 0.2), names=('joint_1', 'joint_2'), positions=None):
    msg = JointTrajectoryMsg(joint_names=list(names))
    msg.header.frame_id = 'beam_base'
    msg.header.stamp.sec = 42
    for i, t in enumerate(times):
        sec, nanosec = divmod(round(t * 1e9), 1_000_000_000)
        point = positions[i] if positions is not None else [0.5 * t, -0.25 * t]
        msg.points.append(
            JointTrajectoryPoint(
                positions=list(point), time_from_start=Duration(sec=sec, nanosec=nanosec)
            )
        )
    return msg


def _status(level=OK, **values):
    defaults = {
        'natural_frequency_hz': 3.0,
        'natural_frequency_hz_std': 0.003,
        'damping_ratio': 0.02,
        'damping_ratio_std': 0.001,
    }
    defaults.update(values)
    status = DiagnosticStatus(level=bytes([level]), name=IDENTIFIER_STATUS)
    status.values = [KeyValue(key=k, value=repr(v)) for k, v in defaults.items()]
    return DiagnosticArray(status=[status])


def _start(ros_graph, **overrides):
    node = ShaperNode(context=ros_graph.context, parameter_overrides=overrides)
    ros_graph.add_node(node)
    return node


def _send(ros_graph, topic, msg):
    ros_graph.publish(topic, msg)
    ros_graph.wait_for_subscribers(topic)
    ros_graph.publish(topic, msg)


def _expected(command, kind, modes):
    return shape_trajectory(trajectory_from_msg(command), design_shaper(kind, modes))


def _assert_is(msg, expected, command):
    got = trajectory_from_msg(msg)
    assert got.joint_names == expected.joint_names
    assert np.allclose(got.time_s, expected.time_s, rtol=0, atol=1e-9)
    assert np.array_equal(got.angles_rad, expected.angles_rad)
    assert msg.header.stamp.sec == command.header.stamp.sec
    assert msg.header.frame_id == command.header.frame_id


def test_fixed_mode_from_parameters(ros_graph):
    got = ros_graph.collect(OUT, JointTrajectoryMsg)
    node = _start(ros_graph, source='parameters', frequency_hz=2.5, damping_ratio=0.03)
    command = _command()
    _send(ros_graph, IN, command)
    assert ros_graph.spin_until(lambda: len(got) >= 1, 10.0)
    _assert_is(got[0], _expected(command, 'zv', [Mode(2.5, 0.03)]), command)
    assert node.published >= 1 and node.description.startswith('ZV for 2.5 Hz')


def test_live_modes_certain_uncertain_invalid_and_two(ros_graph):
    got = ros_graph.collect(OUT, JointTrajectoryMsg)
    node = _start(ros_graph)
    command = _command()
    # No estimate yet: nothing is published, the trajectory is counted as dropped.
    _send(ros_graph, IN, command)
    assert ros_graph.spin_until(lambda: node.dropped >= 1, 10.0)
    assert node.impulses is None and got == []

    # An invalid estimate before any valid one: still no shaper.
    _send(ros_graph, BEAM_PARAMS, _status(ERROR))
    ros_graph.spin_for(0.3)
    assert node.impulses is None

    # A certain estimate: ZV; an uncertain one (std 3 % of the value): the robust EI.
    ros_graph.publish(BEAM_PARAMS, _status())
    assert ros_graph.spin_until(lambda: node.impulses is not None, 10.0)
    assert node.description == 'ZV for 3 Hz (zeta 0.02)'
    ros_graph.publish(BEAM_PARAMS, _status(natural_frequency_hz_std=0.09))
    assert ros_graph.spin_until(lambda: node.description.startswith('EI'), 10.0)
    ei = node.impulses

    # Invalid estimates keep the last good shaper.
    for bad in (
        _status(ERROR),
        _status(natural_frequency_hz_std=4.0),
        _status(damping_ratio=math.nan),
        _status(natural_frequency_hz=-3.0, natural_frequency_hz_std=0.1),
    ):
        ros_graph.publish(BEAM_PARAMS, bad)
    ros_graph.spin_for(0.5)
    assert node.impulses is ei
    ros_graph.publish(IN, command)
    assert ros_graph.spin_until(lambda: len(got) >= 1, 10.0)
    _assert_is(got[0], _expected(command, 'ei', [Mode(3.0, 0.02)]), command)

    # Two modes: their shapers convolved.
    two = _status(
        mode_count=2.0,
        mode_2_natural_frequency_hz=11.0,
        mode_2_natural_frequency_hz_std=0.01,
        mode_2_damping_ratio=0.01,
        mode_2_damping_ratio_std=0.001,
    )
    ros_graph.publish(BEAM_PARAMS, two)
    assert ros_graph.spin_until(lambda: '11 Hz' in node.description, 10.0)
    ros_graph.publish(IN, command)
    assert ros_graph.spin_until(lambda: len(got) >= 2, 10.0)
    _assert_is(got[1], _expected(command, 'zv', [Mode(3.0, 0.02), Mode(11.0, 0.01)]), command)


def test_unshaped_until_the_first_estimate_when_asked(ros_graph):
    got = ros_graph.collect(OUT, JointTrajectoryMsg)
    _start(ros_graph, unshaped_until_estimate=True)
    command = _command()
    _send(ros_graph, IN, command)
    assert ros_graph.spin_until(lambda: len(got) >= 1, 10.0)
    _assert_is(got[0], trajectory_from_msg(command), command)


@pytest.mark.parametrize(
    'command',
    [
        _command(times=(0.0,)),
        _command(times=()),
        _command(times=(0.0, 0.2, 0.1)),
        _command(times=(0.0, 0.1), positions=[[0.0, 0.0], [math.nan, 0.0]]),
        _command(times=(0.0, 0.1), positions=[[0.0, 0.0], [1.0]]),
        _command(times=(0.0, 0.1), names=(), positions=[[], []]),
    ],
    ids=['one point', 'no point', 'times back', 'nan', 'missing position', 'no names'],
)
def test_bad_trajectories_are_dropped(ros_graph, command):
    got = ros_graph.collect(OUT, JointTrajectoryMsg)
    node = _start(ros_graph, source='parameters', frequency_hz=2.0)
    _send(ros_graph, IN, command)
    assert ros_graph.spin_until(lambda: node.dropped >= 1, 10.0)
    ros_graph.spin_for(0.2)
    assert got == [] and node.published == 0


@pytest.mark.parametrize(
    ('overrides', 'error', 'problem'),
    [
        ({'frequency_hz': 0.0}, ConfigError, 'frequency_hz: must be positive'),
        ({'damping_ratio': 1.0}, ConfigError, 'damping_ratio: must be in [0, 1)'),
        ({'shaper': 'zvdd'}, ConfigError, 'shaper: must be one of'),
        ({'source': 'model'}, ConfigError, 'arm_config: needed with source model'),
        ({'max_added_s': 0.0}, ConfigError, 'max_added_s: must be'),
        ({'max_command_s': -1.0}, ConfigError, 'max_command_s: must be'),
        ({'source': 'model', 'arm_config': 'missing.yaml'}, ConfigError, 'missing.yaml'),
        (
            {'source': 'parameters', 'shaper': 'ei', 'damping_ratio': 0.7},
            LumpbeamError,
            'EI shaper: damping ratio 0.7 is above 0.5',
        ),
    ],
)
def test_bad_parameters_stop_the_node_in_one_line(ros_graph, overrides, error, problem):
    with pytest.raises(error) as caught:
        ShaperNode(context=ros_graph.context, parameter_overrides=overrides)
    assert problem in str(caught.value) and '\n' not in str(caught.value)


@pytest.fixture
def arm_file(tmp_path):
    path = tmp_path / 'arm.yaml'
    write_arm_config(path, NOMINAL)
    return path


def _move_command():
    """A move of small_arm(2) to (0.5, -0.8) in 0.3 s, named in reverse order."""
    move = minimum_jerk([0.0, 0.0], [0.5, -0.8], 0.3, step=5e-3)
    positions = move.angles_rad[:, ::-1]
    return _command(times=move.time_s, names=('joint_2', 'joint_1'), positions=positions)


def _model_shaped(command, arm):
    shaped, _ = WorkspaceShaper(arm, 'zv', 2, predict=False).shape(trajectory_from_msg(command))
    return shaped


def test_the_model_shapes_each_move_with_the_latest_identified_arm(ros_graph, arm_file):
    got = ros_graph.collect(OUT, JointTrajectoryMsg)
    node = _start(ros_graph, source='model', arm_config=str(arm_file))
    command = _move_command()
    # Before /arm_params: the arm file's model.
    _send(ros_graph, IN, command)
    assert ros_graph.spin_until(lambda: len(got) >= 1, 10.0)
    from_file = load_arm_config(arm_file)
    _assert_is(got[0], _model_shaped(command, from_file), command)
    # A WARN status and bad values keep it.
    latched = topic_qos(ARM_PARAMS)
    for bad in (
        arm_status_msg(TRUTH, level=1),
        arm_status_msg(TRUTH, link_1_damping_beta=math.nan),
        arm_status_msg(TRUTH, link_2_k_total_nm_per_rad_std=1e9),
    ):
        ros_graph.publish(ARM_PARAMS, bad, latched)
        ros_graph.spin_for(0.3)
    assert 'arm file' in node.description
    # An OK one: the identified arm shapes the next move.
    ros_graph.publish(ARM_PARAMS, arm_status_msg(TRUTH), latched)
    assert ros_graph.spin_until(lambda: ARM_PARAMS in node.description, 10.0)
    before = len(got)
    ros_graph.publish(IN, command)
    assert ros_graph.spin_until(lambda: len(got) > before, 10.0)
    expected = _model_shaped(command, from_file)
    # Other modes: another shaper, another duration.
    assert trajectory_from_msg(got[-1]).duration_s != pytest.approx(expected.duration_s)
    identified = arm_from_status(
        OK, {kv.key: kv.value for kv in arm_status_msg(TRUTH).status[0].values}, from_file
    )
    _assert_is(got[-1], _model_shaped(command, identified), command)


def test_a_command_for_another_arm_is_dropped(ros_graph, arm_file):
    got = ros_graph.collect(OUT, JointTrajectoryMsg)
    node = _start(ros_graph, source='model', arm_config=str(arm_file))
    _send(ros_graph, IN, _command(names=('joint_1', 'wrist')))
    assert ros_graph.spin_until(lambda: node.dropped >= 1, 10.0)
    assert got == []


def test_the_model_shapes_nothing_before_the_first_identified_arm_when_asked(ros_graph, arm_file):
    # The moves before it ring, for the identifier to learn from; the file's model is unused.
    got = ros_graph.collect(OUT, JointTrajectoryMsg)
    node = _start(
        ros_graph, source='model', arm_config=str(arm_file), unshaped_until_estimate=True
    )
    command = _move_command()
    _send(ros_graph, IN, command)
    assert ros_graph.spin_until(lambda: len(got) >= 1, 10.0)
    _assert_is(got[0], trajectory_from_msg(command), command)
    ros_graph.publish(ARM_PARAMS, arm_status_msg(TRUTH, level=1), topic_qos(ARM_PARAMS))
    ros_graph.spin_for(0.3)
    assert node.workspace is None  # a WARN status is no identified arm
    ros_graph.publish(ARM_PARAMS, arm_status_msg(TRUTH), topic_qos(ARM_PARAMS))
    assert ros_graph.spin_until(lambda: ARM_PARAMS in node.description, 10.0)
    before = len(got)  # the command may have gone out twice (_send)
    ros_graph.publish(IN, command)
    assert ros_graph.spin_until(lambda: len(got) > before, 10.0)
    identified = arm_from_status(
        OK, {kv.key: kv.value for kv in arm_status_msg(TRUTH).status[0].values}, NOMINAL
    )
    _assert_is(got[-1], _model_shaped(command, identified), command)


def test_estimates_no_shaper_can_serve_keep_the_last_good_one(ros_graph, capfd):
    # Each once crashed the node (mode_count inf), made a 1 s move 894 s long (5.6e-4 Hz) or
    # sent every move out unshaped without a word (1e300 Hz).
    node = _start(ros_graph)
    ros_graph.publish(BEAM_PARAMS, _status())
    assert ros_graph.spin_until(lambda: node.impulses is not None, 10.0)
    good = node.impulses
    for bad in (
        _status(natural_frequency_hz=5.6e-4, natural_frequency_hz_std=1e-6),
        _status(natural_frequency_hz=1e300, natural_frequency_hz_std=1e297),
    ):
        ros_graph.publish(BEAM_PARAMS, bad)
    ros_graph.publish(BEAM_PARAMS, _status(mode_count=math.inf, natural_frequency_hz=4.0))
    assert ros_graph.spin_until(lambda: '4 Hz' in node.description, 10.0)  # alive
    assert node.impulses is not good and node.impulses.time_s.size == 2
    err = capfd.readouterr().err
    assert 'would add 893' in err and 'more than max_added_s 10 s' in err
    assert "mode_count 'inf' is not a count" in err


def test_a_command_too_long_is_dropped_with_its_reason(ros_graph, capfd):
    # A 2-point command of 9000 s once held the node 121 s at 7.2 GB.
    got = ros_graph.collect(OUT, JointTrajectoryMsg)
    node = _start(ros_graph, source='parameters', frequency_hz=2.0)
    _send(ros_graph, IN, _command(times=(0.0, 9000.0), positions=[[0.0, 0.0], [1.0, 1.0]]))
    assert ros_graph.spin_until(lambda: node.dropped >= 1, 10.0)
    assert got == [] and 'lasts 9000 s, more than max_command_s 600 s' in capfd.readouterr().err


def test_a_fixed_mode_no_shaper_can_serve_stops_the_node_in_one_line(ros_graph):
    with pytest.raises(LumpbeamError, match='too fast to shape') as caught:
        ShaperNode(
            context=ros_graph.context,
            parameter_overrides={'source': 'parameters', 'frequency_hz': 2000.0},
        )
    assert '\n' not in str(caught.value)
