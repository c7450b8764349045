"""Namespaces, remaps and QoS overrides of the nodes' endpoints, on a real graph."""

import pytest
from geometry_msgs.msg import PoseStamped
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from std_msgs.msg import Float64

from lumpbeam_ros.base.errors import ConfigError
from lumpbeam_ros.base.interface import TIP_LOAD, TIP_POSE_PREDICTED, in_namespace
from lumpbeam_ros.core.model.statics import static_tip_deflection
from lumpbeam_ros.nodes import simulator_node
from lumpbeam_ros.nodes.identifier_node import IdentifierNode
from lumpbeam_ros.nodes.simulator_node import SimulatorNode

LATCHED = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)


def test_default_graph_keeps_the_interface_names(ros_graph):
    node = SimulatorNode(context=ros_graph.context)
    names = dict(node.get_publisher_names_and_types_by_node(node.get_name(), '/'))
    assert '/tip_pose_predicted' in names and '/beam_markers' in names
    subscribed = dict(node.get_subscriber_names_and_types_by_node(node.get_name(), '/'))
    assert {'/tip_load', '/beam_params', '/tip_pose'} <= set(subscribed)
    node.destroy_node()


def test_two_beams_in_two_namespaces_do_not_hear_each_other(ros_graph):
    # One namespace given to the constructor, the other as a command-line remap.
    beam_a = SimulatorNode(
        context=ros_graph.context,
        namespace='/beam_a',
        parameter_overrides=[Parameter('initial_load_kg', value=2.0)],
    )
    beam_b = SimulatorNode(
        context=ros_graph.context,
        cli_args=['--ros-args', '-r', '__ns:=/beam_b', '-p', 'initial_load_kg:=2.0'],
    )
    assert beam_b.get_namespace() == '/beam_b'
    for node in (beam_a, beam_b):
        ros_graph.add_node(node)
    got = {
        ns: ros_graph.collect(in_namespace(TIP_POSE_PREDICTED, ns), PoseStamped, 500)
        for ns in ('/beam_a', '/beam_b')
    }
    unspaced = ros_graph.collect(TIP_POSE_PREDICTED, PoseStamped, 500)
    ros_graph.publish(in_namespace(TIP_LOAD, '/beam_a'), Float64(data=4.5), LATCHED)
    ros_graph.publish(in_namespace(TIP_LOAD, '/beam_b'), Float64(data=0.0), LATCHED)
    assert ros_graph.spin_until(
        lambda: (
            beam_a.stream is not None
            and beam_b.stream is not None
            and (beam_a.stream.load_kg, beam_b.stream.load_kg) == (4.5, 0.0)
        ),
        10.0,
    )
    counts = {ns: len(poses) for ns, poses in got.items()}
    assert ros_graph.spin_until(lambda: all(len(got[ns]) > counts[ns] + 5 for ns in got), 10.0)
    # Each beam rests under its own load (the first reading is what hung all along): the
    # static deflection of the model itself, independent of the node.
    for ns, kg, node in (('/beam_a', 4.5, beam_a), ('/beam_b', 0.0, beam_b)):
        z = got[ns][-1].pose.position.z
        assert z == pytest.approx(-static_tip_deflection(node.beam, kg), abs=2e-4), ns
    assert abs(got['/beam_a'][-1].pose.position.z - got['/beam_b'][-1].pose.position.z) > 0.03
    assert unspaced == []  # nothing on the unnamespaced topic
    for node in (beam_a, beam_b):
        node.destroy_node()


def test_a_remap_moves_one_topic(ros_graph):
    node = IdentifierNode(
        context=ros_graph.context, cli_args=['--ros-args', '-r', 'beam_params:=/rig/params']
    )
    published = dict(node.get_publisher_names_and_types_by_node(node.get_name(), '/'))
    assert '/rig/params' in published and '/beam_params' not in published
    node.destroy_node()


def _params_file(tmp_path, node, topic, kind, **policies):
    lines = [f'{node}:', '  ros__parameters:', '    qos_overrides:', f'      {topic}:']
    lines += [f'        {kind}:'] + [f'          {k}: {v}' for k, v in policies.items()]
    path = tmp_path / 'qos.yaml'
    path.write_text('\n'.join(lines) + '\n')
    return str(path)


def test_a_params_file_overrides_the_qos(ros_graph, tmp_path):
    path = _params_file(
        tmp_path,
        'simulator_node',
        '/tip_pose_predicted',
        'publisher',
        depth=7,
        reliability='best_effort',
    )
    node = SimulatorNode(context=ros_graph.context, cli_args=['--ros-args', '--params-file', path])
    ros_graph.add_node(node)
    assert node.get_parameter('qos_overrides./tip_pose_predicted.publisher.depth').value == 7
    (info,) = ros_graph.node.get_publishers_info_by_topic('/tip_pose_predicted')
    assert info.qos_profile.reliability == ReliabilityPolicy.BEST_EFFORT  # as the graph sees it
    # The other endpoints keep the project's profile.
    (load,) = [
        i
        for i in ros_graph.node.get_subscriptions_info_by_topic('/tip_load')
        if i.node_name == node.get_name()
    ]
    assert load.qos_profile.reliability == ReliabilityPolicy.RELIABLE
    assert load.qos_profile.durability == DurabilityPolicy.TRANSIENT_LOCAL
    # A best-effort subscriber now hears it; the default (reliable) profile would refuse it.
    got = ros_graph.collect(
        '/tip_pose_predicted',
        PoseStamped,
        QoSProfile(depth=10, reliability=ReliabilityPolicy.BEST_EFFORT),
    )
    assert ros_graph.spin_until(lambda: len(got) >= 3, 10.0)
    node.destroy_node()


def test_overrides_resolve_in_the_namespace(ros_graph, tmp_path):
    # A file for any node (as config/*.yaml are); the names resolve in the namespace.
    path = _params_file(tmp_path, '/**', '/beam_a/tip_load', 'subscription', depth=3)
    node = SimulatorNode(
        context=ros_graph.context,
        namespace='/beam_a',
        cli_args=['--ros-args', '--params-file', path],
    )
    assert node.get_parameter('qos_overrides./beam_a/tip_load.subscription.depth').value == 3
    assert not node.has_parameter('qos_overrides./tip_load.subscription.depth')
    node.destroy_node()


@pytest.mark.parametrize(
    ('policy', 'value', 'reason'),
    [
        ('depth', 0, 'depth 0 < 1'),
        ('depth', "'many'", 'expecting type'),
        ('reliability', 'sometimes', 'sometimes'),
    ],
)
def test_a_bad_override_stops_the_node_naming_the_parameter(
    ros_graph, tmp_path, policy, value, reason
):
    path = _params_file(
        tmp_path, 'simulator_node', '/tip_pose_predicted', 'publisher', **{policy: value}
    )
    with pytest.raises(ConfigError, match=reason) as raised:
        SimulatorNode(context=ros_graph.context, cli_args=['--ros-args', '--params-file', path])
    assert raised.value.key == 'qos_overrides./tip_pose_predicted.publisher'


def test_main_exits_2_on_a_bad_override(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv('ROS_DOMAIN_ID', '231')
    path = _params_file(tmp_path, 'simulator_node', '/tip_load', 'subscription', depth=-1)
    assert simulator_node.main(['simulator_node', '--ros-args', '--params-file', path]) == 2
    err = capsys.readouterr().err
    assert 'qos_overrides./tip_load.subscription' in err and 'Traceback' not in err
