import math

import pytest
import rclpy
from rcl_interfaces.msg import ParameterType
from rclpy.context import Context
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient

from lumpbeam_ros.base.errors import ConfigError
from lumpbeam_ros.base.resources import config_path
from lumpbeam_ros.base.schema import Bounds, ParameterSchema, ParameterSpec
from lumpbeam_ros.nodes.camera_node import CameraNode
from lumpbeam_ros.nodes.identifier_node import IdentifierNode
from lumpbeam_ros.nodes.params.camera_params import CAMERA_SCHEMA
from lumpbeam_ros.nodes.params.identifier_params import IDENTIFIER_SCHEMA
from lumpbeam_ros.nodes.params.reference import SCHEMAS
from lumpbeam_ros.nodes.params.simulator_params import SIMULATOR_SCHEMA
from lumpbeam_ros.nodes.ros_parameters import declare_parameters, describe, undeclared_in_schema
from lumpbeam_ros.nodes.simulator_node import SimulatorNode

PROBE = ParameterSchema(
    'probe_node',
    'A node for the tests.',
    (
        ParameterSpec(
            'gain', 'double', 1.0, 'a gain', 'N', Bounds(0.0, low_open=True), read_only=False
        ),
        ParameterSpec('size', 'int', 3, 'a size', bounds=Bounds(1, 10), read_only=False),
        ParameterSpec('mode', 'string', 'a', 'a mode', choices=('a', 'b'), read_only=False),
        ParameterSpec('xyz', 'double[]', (0.0, 0.0, 0.0), 'a point', 'm', length=3),
        ParameterSpec('fixed', 'double', 2.0, 'set at start only'),
    ),
)


@pytest.fixture
def make_node():
    """Builds plain nodes on private contexts, with ``--ros-args`` and overrides."""
    contexts = []

    def make(schema=PROBE, args=(), on_change=None, **overrides):
        context = Context()
        rclpy.init(context=context, args=['node', *args], domain_id=0)
        contexts.append(context)
        node = Node(
            schema.node,
            context=context,
            parameter_overrides=[Parameter(k, value=v) for k, v in overrides.items()],
        )
        return node, declare_parameters(node, schema, on_change)

    yield make
    for context in contexts:
        rclpy.shutdown(context=context)


@pytest.mark.parametrize('schema', SCHEMAS, ids=lambda s: s.node)
def test_descriptors_carry_type_range_and_read_only(make_node, schema):
    node, values = make_node(schema)
    assert values == {
        name: list(v) if isinstance(v, tuple) else v for name, v in schema.defaults().items()
    }
    for spec in schema:
        descriptor = node.describe_parameter(spec.name)
        assert descriptor.read_only == spec.read_only
        assert descriptor.description.startswith(spec.description)
        assert descriptor.additional_constraints == spec.constraints()
        ranges = list(descriptor.floating_point_range) + list(descriptor.integer_range)
        if spec.bounds is None or spec.kind == 'double[]':
            assert ranges == []
            continue
        (bound,) = ranges
        assert bound.from_value == (-math.inf if spec.bounds.low is None else spec.bounds.low)
        if spec.bounds.high is not None:
            assert bound.to_value == spec.bounds.high
        kinds = {'int': ParameterType.PARAMETER_INTEGER, 'double': ParameterType.PARAMETER_DOUBLE}
        assert descriptor.type == kinds[spec.kind]


def test_describe_states_the_unit():
    assert describe(PROBE['gain']).description == 'a gain [N]'
    assert describe(PROBE['size']).integer_range[0].to_value == 10


def test_a_params_file_loads(make_node, tmp_path):
    path = tmp_path / 'probe.yaml'
    path.write_text(
        '/**:\n  ros__parameters:\n    gain: 2\n    mode: b\n    xyz: [1.0, 2.0, 3.0]\n'
    )
    node, values = make_node(args=['--ros-args', '--params-file', str(path), '-p', 'size:=7'])
    assert values == {'gain': 2.0, 'size': 7, 'mode': 'b', 'xyz': [1.0, 2.0, 3.0], 'fixed': 2.0}
    assert node.get_parameter('gain').type_ == Parameter.Type.DOUBLE  # YAML's 2 for 2.0


@pytest.mark.parametrize('schema', SCHEMAS, ids=lambda s: s.node)
def test_the_package_config_files_load(make_node, schema):
    args = ['--ros-args', '--params-file', str(config_path(schema.config_file))]
    _, values = make_node(schema, args)
    assert values == {
        name: list(v) if isinstance(v, tuple) else v for name, v in schema.defaults().items()
    }


@pytest.mark.parametrize(
    ('overrides', 'message'),
    [
        ({'gain': -1.0}, 'probe_node parameters: gain: must be positive, got -1.0'),
        ({'gain': 0.0}, 'gain: must be positive, got 0.0'),  # in the descriptor's [0, inf]
        ({'gain': 'high'}, "gain: must be a number, got 'high'"),
        ({'size': 11}, 'size: must be in [1, 10], got 11'),
        ({'mode': 'c'}, "mode: must be one of a, b, got 'c'"),
        ({'xyz': [1.0, 2.0]}, 'xyz: must be a list of 3 finite numbers'),
        ({'fixed': math.nan}, 'fixed: must be finite, got nan'),
    ],
)
def test_a_bad_value_at_start_is_refused_in_one_line(make_node, overrides, message):
    with pytest.raises(ConfigError) as caught:
        make_node(**overrides)
    assert message in str(caught.value) and '\n' not in str(caught.value)


@pytest.mark.parametrize(
    ('name', 'value', 'reason'),
    [
        ('gain', -1.0, 'gain out of range'),  # rclpy's descriptor check
        ('gain', 0.0, 'gain: must be positive'),  # the schema's, in the on-set callback
        ('gain', math.nan, 'gain'),
        ('gain', 'high', 'Wrong parameter type'),
        ('size', 0, 'size out of range'),
        ('mode', 'c', "mode: must be one of a, b, got 'c'"),
        ('fixed', 3.0, 'read-only'),
    ],
)
def test_a_bad_set_is_refused_with_a_reason_and_the_old_value_kept(make_node, name, value, reason):
    node, _ = make_node()
    before = node.get_parameter(name).value
    (result,) = node.set_parameters([Parameter(name, value=value)])
    assert not result.successful and reason in result.reason
    assert node.get_parameter(name).value == before


def test_a_good_set_reaches_the_hook_and_the_hook_may_refuse(make_node):
    seen = []

    def on_change(changes):
        seen.append(dict(changes))
        return 'size 9 is unlucky' if changes.get('size') == 9 else None

    node, _ = make_node(on_change=on_change)
    assert node.set_parameters([Parameter('size', value=4)])[0].successful
    (refused,) = node.set_parameters([Parameter('size', value=9)])
    assert not refused.successful and refused.reason == 'size 9 is unlucky'
    assert node.get_parameter('size').value == 4
    assert seen == [{'size': 4}, {'size': 9}]


def test_the_parameter_service_refuses_with_the_reason(ros_graph):
    # The path `ros2 param set` takes: the node's set_parameters service, from another node.
    node = SimulatorNode(context=ros_graph.context)
    ros_graph.add_node(node)
    client = AsyncParameterClient(ros_graph.node, node.get_fully_qualified_name())
    assert ros_graph.spin_until(lambda: client.services_are_ready(), 10.0)
    future = client.set_parameters(
        [Parameter('rate_hz', value=5000.0), Parameter('tick_rate_hz', value=25.0)]
    )
    assert ros_graph.spin_until(future.done, 10.0)
    refused, accepted = future.result().results
    assert not refused.successful and 'rate_hz' in refused.reason
    assert accepted.successful
    assert node.get_parameter('rate_hz').value == 180.0
    assert node.get_parameter('tick_rate_hz').value == 25.0


def test_read_only_identifier_parameters_cannot_be_set(ros_graph):
    node = IdentifierNode(context=ros_graph.context)
    (result,) = node.set_parameters([Parameter('publish_rate_hz', value=5.0)])
    assert not result.successful and 'read-only' in result.reason
    assert node.get_parameter('publish_rate_hz').value == 2.0
    node.destroy_node()


@pytest.mark.parametrize(
    ('node_class', 'schema'),
    [
        (CameraNode, CAMERA_SCHEMA),
        (IdentifierNode, IDENTIFIER_SCHEMA),
        (SimulatorNode, SIMULATOR_SCHEMA),
    ],
    ids=['camera', 'identifier', 'simulator'],
)
def test_each_node_declares_exactly_its_schema(ros_graph, node_class, schema):
    node = node_class(context=ros_graph.context)
    assert node.get_name() == schema.node
    assert undeclared_in_schema(node, schema) == []
    assert all(node.has_parameter(name) for name in schema.names)
    node.destroy_node()
