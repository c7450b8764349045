"""The diagnosis node on a private graph: bad input, a live ring-down, adoption."""

import math

import pytest
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import PoseStamped
from rcl_interfaces.msg import ParameterDescriptor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import Float64

from lumpbeam_ros.base.interface import DIAGNOSIS_STATUS as STATUS_NAME
from lumpbeam_ros.base.interface import MODEL_DISCREPANCY as TOPIC
from lumpbeam_ros.core.bagio.convert import pitch_to_quaternion
from lumpbeam_ros.core.diagnose.live import LiveDiagnosis, Stretch
from lumpbeam_ros.core.model.parameters import load_beam_config
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, simulate_experiment
from lumpbeam_ros.nodes.diagnosis_node import DiagnosisNode
from lumpbeam_ros.nodes.simulator_node import SimulatorNode

LATCHED = QoSProfile(
    depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.TRANSIENT_LOCAL
)
LATENCY = 'effects.sensor_latency.latency_s'
#: Generous: a diagnosis takes seconds, tens of them on a loaded machine.
DIAGNOSIS_TIMEOUT_S = 300.0


def _pose(t, z, pitch, frame='beam_base'):
    msg = PoseStamped()
    msg.header.frame_id = frame
    msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(round(t * 1e9), 1_000_000_000)
    msg.pose.position.z = z
    q = msg.pose.orientation
    q.x, q.y, q.z, q.w = pitch_to_quaternion(pitch)
    return msg


def _start(ros_graph, **overrides):
    node = DiagnosisNode(
        context=ros_graph.context,
        parameter_overrides={'worker': 'thread', 'status_period_s': 0.1, **overrides},
    )
    ros_graph.add_node(node)
    return node


def _statuses(messages):
    return [s for m in messages for s in m.status if s.name == STATUS_NAME]


def _values(status):
    return {kv.key: kv.value for kv in status.values}


def test_predicted_poses_without_measured_ones_say_what_is_missing(ros_graph):
    got = ros_graph.collect(TOPIC, DiagnosticArray)
    node = _start(ros_graph)
    for i in range(20):
        ros_graph.publish('/tip_pose_predicted', _pose(10.0 + i / 180, -0.07, 0.04))
        ros_graph.spin_for(0.01)

    def said():
        return any(
            _values(s).get('missing_input') == '/tip_pose'
            and 'only /tip_pose_predicted' in s.message
            for s in _statuses(got)
        )

    assert ros_graph.spin_until(said, 30.0)
    assert node.buffer.predicted_count > 0 and node.diagnoses == 0
    assert _statuses(got)[-1].level == bytes([3])  # STALE: nothing diagnosed


def test_nan_and_wrong_frame_poses_are_dropped_and_counted(ros_graph):
    got = ros_graph.collect(TOPIC, DiagnosticArray)
    node = _start(ros_graph)
    ros_graph.publish('/tip_pose', _pose(1.0, -0.07, 0.04))
    ros_graph.wait_for_subscribers('/tip_pose')
    for msg in (
        _pose(1.0, -0.07, 0.04),
        _pose(1.1, math.nan, 0.04),
        _pose(1.2, -0.07, 0.04, frame='camera'),
        _pose(1.3, -0.07, 0.04),
    ):
        ros_graph.publish('/tip_pose', msg)
    assert ros_graph.spin_until(lambda: node.non_finite == 1 and node.wrong_frame == 1, 30.0)
    assert ros_graph.spin_until(lambda: node.buffer.measured_count >= 2, 30.0)
    assert list(node.buffer.measured.t)[-1] == pytest.approx(1.3)
    assert all(math.isfinite(z) for z in node.buffer.measured.z)
    assert ros_graph.spin_until(
        lambda: any(_values(s).get('samples_wrong_frame') == '1' for s in _statuses(got)), 30.0
    )


def _feed(ros_graph, nodes, t, z, pitch, loads, offset, chunk=18):
    """Plays poses and load changes as a player does: in stamp order, /clock before each."""
    pending = list(loads)
    diag = nodes[0]
    for start in range(0, t.size, chunk):
        end = min(start + chunk, t.size)
        for i in range(start, end):
            while pending and pending[0][0] <= t[i]:
                when, kg = pending.pop(0)
                ros_graph.set_clock(nodes, offset + when, 30.0)
                ros_graph.publish('/tip_load', Float64(data=kg), LATCHED)
            ros_graph.publish('/tip_pose', _pose(offset + t[i], z[i], pitch[i]), 200)
        ros_graph.set_clock(nodes, offset + t[end - 1], 30.0)
        assert ros_graph.spin_until(lambda end=end: diag.buffer.measured_count >= end - 1, 30.0)


def test_a_live_ring_down_names_the_hidden_latency_and_the_simulator_adopts_it(ros_graph):
    beam, drop = load_beam_config()
    measured, _ = simulate_experiment(
        beam, drop, SynthOptions(duration_s=4.5, effects={'sensor_latency': 0.015})
    )
    got = ros_graph.collect(TOPIC, DiagnosticArray)
    simulator = SimulatorNode(
        context=ros_graph.context,
        parameter_overrides=[Parameter('use_sim_time', value=True)],
    )
    ros_graph.add_node(simulator)
    node = _start(
        ros_graph,
        use_sim_time=True,
        adopt=True,
        worker='process',
        **{'ring_down.decay_s': 2.3},
    )
    ros_graph.publish('/tip_pose', _pose(1.0, -0.07, 0.04), 200)
    ros_graph.publish('/tip_load', Float64(data=drop.load_kg), LATCHED)
    ros_graph.wait_for_subscribers('/tip_pose')
    ros_graph.wait_for_subscribers('/tip_load', 2)
    _feed(
        ros_graph,
        [node, simulator],
        measured.t[1:],
        measured.z[1:],
        measured.pitch[1:],
        [(0.0, drop.load_kg), (drop.release_time_s, 0.0)],
        offset=100.0,
    )
    assert ros_graph.spin_until(lambda: node.last is not None, DIAGNOSIS_TIMEOUT_S), node.status()
    assert node.last.missing_effect == 'sensor_latency'
    # The release is dated by the poses sent around it, up to one pose's spacing early: the
    # delay found is as much too long at most.
    assert 0.0135 <= node.last.effect_parameters['latency_s'] <= 0.015 + 1 / 180 + 0.0015
    assert ros_graph.spin_until(lambda: node.adoption.startswith('adopted'), 60.0), node.adoption
    adopted = simulator.get_parameter(LATENCY).value
    assert adopted == node.last.effect_parameters['latency_s']
    assert simulator.beam.effects.latency_s == adopted
    warned = [s for s in _statuses(got) if s.level == bytes([1])]
    assert warned and _values(warned[-1])['missing_effects'] == 'sensor_latency'
    assert float(_values(warned[-1])['gap_after_rms_m']) < float(
        _values(warned[-1])['gap_before_rms_m']
    )


def _found(after_m):
    return LiveDiagnosis(
        'sensor_latency',
        (('sensor_latency', {'latency_s': 0.015}),),
        3e-3,
        after_m,
        'test',
        Stretch(1.0, 4.3, 2.0),
    )


def test_a_simulator_that_refuses_the_parameters_is_one_message_and_no_adoption(ros_graph):
    # A simulator whose latency is fixed at start: its parameter service refuses a change.
    fixed = Node('simulator_node', context=ros_graph.context)
    fixed.declare_parameter(LATENCY, 0.0, ParameterDescriptor(read_only=True))
    ros_graph.add_node(fixed)
    node = _start(ros_graph, adopt=True)
    assert ros_graph.spin_until(node._simulator_parameters.services_are_ready, 30.0)
    node.offer_adoption(_found(2e-5), 3e-3)
    assert ros_graph.spin_until(lambda: 'refused' in node.adoption, 30.0), node.adoption
    assert node.adoption.startswith(f'simulator_node refused the adoption: {LATENCY}')
    assert fixed.get_parameter(LATENCY).value == 0.0


def test_a_model_that_fits_worse_than_the_running_one_is_not_adopted(ros_graph):
    simulator = SimulatorNode(context=ros_graph.context)
    ros_graph.add_node(simulator)
    node = _start(ros_graph, adopt=True)
    assert ros_graph.spin_until(node._simulator_parameters.services_are_ready, 30.0)
    node.offer_adoption(_found(4e-3), 3e-3)
    assert node.adoption.startswith('not adopted: the augmented model')
    node.offer_adoption(_found(2e-5), math.nan)  # no prediction to compare with
    assert node.adoption.startswith('not adopted: no simulator prediction')
    ros_graph.spin_for(0.5)
    assert simulator.get_parameter(LATENCY).value == 0.0
    node.offer_adoption(_found(2e-5), 3e-3)
    assert ros_graph.spin_until(lambda: node.adoption.startswith('adopted'), 30.0)
    assert simulator.beam.effects.latency_s == 0.015


def test_a_window_without_a_release_is_reported_not_diagnosed(ros_graph):
    got = ros_graph.collect(TOPIC, DiagnosticArray)
    node = _start(ros_graph, trigger='window', window_s=2.0)
    ros_graph.publish('/tip_load', Float64(data=4.5), LATCHED)
    ros_graph.publish('/tip_pose', _pose(1.0, -0.07, 0.04), 200)
    ros_graph.wait_for_subscribers('/tip_pose')
    ros_graph.wait_for_subscribers('/tip_load')
    for i in range(181, 181 + 3 * 180):
        ros_graph.publish('/tip_pose', _pose(i / 180, -0.07, 0.04), 200)
        if i % 50 == 0:
            ros_graph.spin_for(0.02)
    # Stamps on another clock than the node's: the reading is dated by the poses around it.
    assert ros_graph.spin_until(lambda: len(node.buffer.loads) == 1, 30.0)

    def said():
        return any('no load change between' in s.message for s in _statuses(got))

    assert ros_graph.spin_until(said, 30.0)
    assert node.diagnoses == 0


def test_repeated_and_late_poses_are_counted_not_dropped_silently(ros_graph):
    node = _start(ros_graph)
    for t in (1.0, 1.1, 1.1, 1.05, 1.2):  # one repeated stamp, one late one
        node._on_pose(_pose(t, -0.07, 0.04))
    assert node.buffer.measured_count == 3
    assert _values(node.status())['samples_out_of_order'] == '2'
    node._on_pose(_pose(1.2 - 1000.0, -0.07, 0.04))  # a loop back, once the next pose agrees
    node._on_pose(_pose(1.21 - 1000.0, -0.07, 0.04))
    assert node.buffer.measured.counts.resets == 1 and len(node.buffer.measured) == 2
    assert _values(node.status())['samples_out_of_order'] == '2'


def test_a_verdict_from_before_the_clock_went_back_is_repeated_as_stale_not_as_new(ros_graph):
    node = _start(ros_graph)
    node._on_load(Float64(data=4.5))
    for t in (10.0, 10.01, 10.02):
        node._on_pose(_pose(t, -0.07, 0.04))
    node.last = _found(2e-5)
    assert node.status().level == bytes([1])  # WARN: the latency found
    for t in (0.0, 0.01):  # the bag looped
        node._on_pose(_pose(t, -0.07, 0.04))
    status = node.status()
    assert status.level == bytes([3]) and status.message.startswith('the clock went back')
    assert _values(status)['missing_effect'] == 'sensor_latency'  # what it was, still said
