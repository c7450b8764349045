"""Property-based messages on the nodes' topics (hypothesis): what any message may not do.

Each property feeds one node, built once per test, the messages hypothesis draws (values
from the extremes a float can take, texts that are no numbers, keys missing or repeated,
commands of any length and shape) through the callbacks the executor calls, and checks
after each message:

- no exception leaves a callback (the node is alive);
- nothing it publishes is non-finite or outside its declared range: the shaper's shaper
  adds at most ``max_added_s``, its commands are finite and no longer than the input plus
  that; the simulator's beam keeps a finite load it can carry and a stiffness within a
  factor of 10 of its own, and its tick after them returns;
- every command the shaper is given is published or counted as dropped;
- the identifier and the diagnosis node keep or count every pose, hold only finite loads,
  and publish no infinity, nor at OK a standard deviation that is not a positive number;
- the camera node survives any camera info (sizes, K, distortion) and any image (sizes,
  steps, encodings, lengths) and publishes no non-finite pose.

``LUMPBEAM_FUZZ_CASES`` sets the examples per property (500; ``make fuzz`` runs thousands).
"""

from __future__ import annotations

import math
import os
from collections import Counter

import numpy as np
import pytest
from builtin_interfaces.msg import Duration
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import PoseStamped
from rclpy.serialization import serialize_message
from sensor_msgs.msg import CameraInfo, Image, JointState
from std_msgs.msg import Float64
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from lumpbeam_ros.base.interface import IDENTIFIER_STATUS
from lumpbeam_ros.core.model.adopt import MAX_STIFFNESS_FACTOR
from lumpbeam_ros.core.model.statics import carries
from lumpbeam_ros.nodes.camera_node import CameraNode
from lumpbeam_ros.nodes.diagnosis_node import DiagnosisNode
from lumpbeam_ros.nodes.identifier_node import IdentifierNode
from lumpbeam_ros.nodes.shaper_node import ShaperNode
from lumpbeam_ros.nodes.simulator_node import SimulatorNode
from lumpbeam_ros.nodes.trajectory_messages import trajectory_from_msg

hypothesis = pytest.importorskip('hypothesis')
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

CASES = int(os.environ.get('LUMPBEAM_FUZZ_CASES', '500'))
#: Messages given to each node over the module's run, printed at its end (``make fuzz``).
GIVEN: Counter[str] = Counter()


@pytest.fixture(scope='module', autouse=True)
def _tally():
    yield
    print(f'\nfuzz_topics: messages per node {dict(GIVEN)}, {sum(GIVEN.values())} in all')


#: One node serves every example of its property: building one per example would be most
#: of the run.
FUZZ = settings(
    max_examples=CASES,
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
KEYS = (
    'natural_frequency_hz',
    'natural_frequency_hz_std',
    'damping_ratio',
    'damping_ratio_std',
    'mode_count',
    'mode_2_natural_frequency_hz',
    'mode_2_natural_frequency_hz_std',
    'mode_2_damping_ratio',
    'mode_2_damping_ratio_std',
    'stiffness_total_nm_per_rad',
)
#: Numbers from every corner: the extremes, the plausible and the absurd.
numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(1e-6, 1e3),
    st.sampled_from([0.0, -0.0, 1e-300, 5.6e-4, 0.02, 3.0, 499.0, 501.0, 3899.1, 1e300]),
)
texts = st.one_of(numbers.map(repr), st.text(max_size=8))


def _status(level: int, values: dict[str, str]) -> DiagnosticArray:
    status = DiagnosticStatus(level=bytes([level]), name=IDENTIFIER_STATUS)
    status.values = [KeyValue(key=k, value=v) for k, v in values.items()]
    return DiagnosticArray(status=[status])


statuses = st.builds(
    _status,
    st.integers(0, 3),
    st.dictionaries(st.sampled_from(KEYS), texts, max_size=len(KEYS)),
)


def _point(t: float, positions: list[float]) -> JointTrajectoryPoint:
    whole = math.isfinite(t) and abs(t) < 1e9
    sec, nanosec = divmod(round(t * 1e9), 10**9) if whole else (0, 0)
    return JointTrajectoryPoint(
        positions=positions, time_from_start=Duration(sec=int(sec), nanosec=int(nanosec))
    )


@st.composite
def commands(draw: st.DrawFn) -> JointTrajectory:
    """A command of 0 to 40 points: times anywhere, positions anything, names mostly right."""
    names = draw(st.sampled_from([['joint_1'], ['joint_1', 'joint_2'], [], ['joint_1', 'x']]))
    count = draw(st.integers(0, 40))
    times = draw(
        st.one_of(
            st.lists(st.floats(0.0, 1e4), min_size=count, max_size=count).map(sorted),
            st.lists(numbers, min_size=count, max_size=count),
        )
    )
    width = len(names) if draw(st.booleans()) else draw(st.integers(0, 3))
    rows = draw(
        st.lists(
            st.lists(st.one_of(numbers, st.floats(-3.0, 3.0)), min_size=width, max_size=width),
            min_size=count,
            max_size=count,
        )
    )
    msg = JointTrajectory(joint_names=names)
    msg.points = [_point(t, row) for t, row in zip(times, rows, strict=True)]
    return msg


def _capturing(node, publisher):
    """The node, with what ``publisher`` would send kept in ``node.sent`` instead."""
    node.sent = []
    publisher.publish = node.sent.append
    return node


@pytest.fixture
def shaper(ros_graph):
    node = ShaperNode(context=ros_graph.context)
    yield _capturing(node, node._output)
    node.destroy_node()


@FUZZ
@given(messages=st.lists(st.one_of(statuses, commands()), min_size=1, max_size=6))
def test_the_shaper_takes_any_message(shaper, messages):
    limits = shaper.limits
    GIVEN['shaper_node'] += len(messages)
    for msg in messages:
        sent, dropped = len(shaper.sent), shaper.dropped
        if isinstance(msg, DiagnosticArray):
            shaper._on_params(msg)
        else:
            shaper._on_trajectory(msg)
            assert len(shaper.sent) + shaper.dropped == sent + dropped + 1
            if len(shaper.sent) > sent:
                out, command = trajectory_from_msg(shaper.sent[-1]), trajectory_from_msg(msg)
                assert np.all(np.isfinite(out.angles_rad)) and np.all(np.isfinite(out.time_s))
                assert out.duration_s <= command.duration_s + limits.max_added_s + 1e-6
        impulses = shaper.impulses
        if impulses is not None:
            assert np.all(np.isfinite(impulses.time_s)) and np.all(np.isfinite(impulses.amplitude))
            assert impulses.duration_s <= limits.max_added_s


@pytest.fixture
def simulator(ros_graph):
    node = SimulatorNode(context=ros_graph.context, parameter_overrides={'adopt_identified': True})
    yield node
    node.destroy_node()


#: Loads: what a rig hangs, what sags the beam past the model's regime (refused: 30 kg and up
#: on the paper's beam), and what no beam carries.
loads = st.one_of(
    st.floats(0.0, 100.0),
    st.sampled_from([math.nan, math.inf, -math.inf, -1.0, -0.0, 1e4, 1e6, 1e300, 1e308]),
).map(lambda kg: Float64(data=kg))


# A tick simulates the beam under what it took: one tick per example.
@FUZZ
@given(messages=st.lists(st.one_of(statuses, loads), min_size=1, max_size=6))
def test_the_simulator_takes_any_load_and_estimate(simulator, messages):
    model = simulator.model
    own = model._base_beam.segment_stiffness() / model._base_beam.n_segments
    GIVEN['simulator_node'] += len(messages)
    for msg in messages:
        if isinstance(msg, Float64):
            model._on_load(msg)
        else:
            model._on_beam_params(msg)
    simulator._tick()
    beam = model.beam
    assert math.isfinite(model._load_kg) and carries(beam, model._load_kg)
    if beam.stiffness_source == 'identified':
        ratio = beam.k_total_nm_per_rad / own
        assert 1 / MAX_STIFFNESS_FACTOR <= ratio <= MAX_STIFFNESS_FACTOR


# -- the identifier, the diagnosis and the camera ---------------------------------------------

frames = st.sampled_from(['beam_base', 'beam_base', 'beam_base', 'camera', ''])


@st.composite
def poses(draw: st.DrawFn) -> PoseStamped:
    """A tip pose: mostly near a ringing beam's, with any stamp, value or frame at times."""
    msg = PoseStamped()
    msg.header.frame_id = draw(frames)
    msg.header.stamp.sec = draw(st.one_of(st.integers(0, 20), st.integers(0, 2**31 - 1)))
    msg.header.stamp.nanosec = draw(st.integers(0, 999_999_999))
    position = st.one_of(st.floats(-0.2, 0.2), numbers)
    msg.pose.position.x, msg.pose.position.z = draw(position), draw(position)
    q = msg.pose.orientation
    q.x, q.y, q.z, q.w = draw(
        st.one_of(
            st.floats(-0.05, 0.05).map(lambda a: (0.0, math.sin(a), 0.0, math.cos(a))),
            st.tuples(numbers, numbers, numbers, numbers),
        )
    )
    return msg


@st.composite
def joint_states(draw: st.DrawFn) -> JointState:
    """Joint states whose names and positions may not pair up."""
    names = draw(st.lists(st.sampled_from(['joint_1', 'joint_2', 'x']), max_size=3))
    count = len(names) if draw(st.booleans()) else draw(st.integers(0, 4))
    return JointState(name=names, position=draw(st.lists(numbers, min_size=count, max_size=count)))


def _is_number_or_text(value: str) -> bool:
    try:
        number = float(value)
    except ValueError:
        return True  # a reason, a name
    return not math.isinf(number)


def _finite_when_ok(msg: DiagnosticArray) -> None:
    """What any status the product publishes holds: no infinity; at OK, finite figures."""
    for status in msg.status:
        for kv in status.values:
            assert _is_number_or_text(kv.value), (kv.key, kv.value)
            if status.level == bytes([0]) and kv.key.endswith('_std'):
                assert math.isfinite(float(kv.value)) and float(kv.value) > 0.0, kv


@pytest.fixture
def identifier(ros_graph):
    node = IdentifierNode(context=ros_graph.context)
    yield _capturing(node, node._output)
    node.destroy_node()


@FUZZ
@given(messages=st.lists(st.one_of(poses(), loads, joint_states()), min_size=1, max_size=30))
def test_the_identifier_takes_any_pose_load_and_joint_state(identifier, messages):
    GIVEN['identifier_node'] += len(messages)
    for msg in messages:
        if isinstance(msg, PoseStamped):
            identifier._on_pose(msg)
        elif isinstance(msg, Float64):
            identifier._on_load(msg)
        else:
            identifier._on_joint_state(msg)
    identifier._on_timer()
    _finite_when_ok(identifier.sent[-1])
    counts = identifier.window.counts
    assert counts.kept + counts.dropped == counts.received
    assert len(identifier.window) <= identifier.window.poses._capacity


@pytest.fixture
def diagnosis(ros_graph):
    node = DiagnosisNode(context=ros_graph.context, parameter_overrides={'worker': 'thread'})
    node._output.publish = lambda msg: _finite_when_ok(msg)
    yield node
    node.destroy_node()


@FUZZ
@given(messages=st.lists(st.one_of(poses(), poses(), loads), min_size=1, max_size=30))
def test_the_diagnosis_node_takes_any_pose_and_load(diagnosis, messages):
    GIVEN['diagnosis_node'] += len(messages)
    for i, msg in enumerate(messages):
        if isinstance(msg, Float64):
            diagnosis._on_load(msg)
        elif i % 2:
            diagnosis._on_predicted(msg)
        else:
            diagnosis._on_pose(msg)
    diagnosis._poll()
    diagnosis._publish_status()
    buffer = diagnosis.buffer
    assert all(math.isfinite(t) and math.isfinite(kg) and kg >= 0 for t, kg in buffer.loads[1:])
    counts = buffer.measured.counts
    assert counts.kept + counts.dropped == counts.received


def _camera_info(draw: st.DrawFn) -> bytes:
    msg = CameraInfo(width=draw(st.integers(0, 70000)), height=draw(st.integers(0, 70000)))
    msg.k = draw(st.lists(numbers, min_size=9, max_size=9))
    msg.d = draw(st.lists(numbers, max_size=8))
    msg.distortion_model = draw(st.sampled_from(['plumb_bob', 'rational_polynomial', 'x', '']))
    return serialize_message(msg)


def _image(draw: st.DrawFn) -> bytes:
    width, height = draw(st.integers(0, 64)), draw(st.integers(0, 64))
    step = draw(st.one_of(st.just(width), st.integers(0, 200)))
    size = draw(st.one_of(st.just(step * height), st.integers(0, 5000)))
    msg = Image(
        width=width,
        height=height,
        step=step,
        encoding=draw(st.sampled_from(['mono8', 'bgr8', 'rgb8', 'mono16', '16UC1', 'x'])),
        data=draw(st.binary(min_size=size, max_size=size)),
    )
    msg.header.stamp.sec = draw(st.integers(0, 2**31 - 1))
    return serialize_message(msg)


@st.composite
def camera_messages(draw: st.DrawFn) -> tuple[str, bytes]:
    """A serialized camera info or image, as the camera node receives them."""
    if draw(st.booleans()):
        return 'info', _camera_info(draw)
    return 'image', _image(draw)


@pytest.fixture
def camera(ros_graph):
    node = CameraNode(context=ros_graph.context)
    yield _capturing(node, node.pose_publisher)
    node.destroy_node()


@FUZZ
@given(messages=st.lists(camera_messages(), min_size=1, max_size=6))
def test_the_camera_node_takes_any_camera_info_and_image(camera, messages):
    GIVEN['camera_node'] += len(messages)
    for kind, data in messages:
        if kind == 'info':
            camera.on_camera_info(data)
        else:
            camera.on_image(data)
    camera.publish_diagnostics()
    for pose in camera.sent:  # random pixels may show no board: nothing fabricated
        p = pose.pose.position
        assert all(math.isfinite(v) for v in (p.x, p.y, p.z))
