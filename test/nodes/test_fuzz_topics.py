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
- every command the shaper is given is published or counted as dropped.

``LUMPBEAM_FUZZ_CASES`` sets the examples per property (200; ``make fuzz`` runs thousands).
"""

from __future__ import annotations

import math
import os

import numpy as np
import pytest
from builtin_interfaces.msg import Duration
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from std_msgs.msg import Float64
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from lumpbeam_ros.base.interface import IDENTIFIER_STATUS
from lumpbeam_ros.core.model.adopt import MAX_STIFFNESS_FACTOR
from lumpbeam_ros.core.model.statics import carries
from lumpbeam_ros.nodes.shaper_node import ShaperNode
from lumpbeam_ros.nodes.simulator_node import SimulatorNode
from lumpbeam_ros.nodes.trajectory_messages import trajectory_from_msg

hypothesis = pytest.importorskip('hypothesis')
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

CASES = int(os.environ.get('LUMPBEAM_FUZZ_CASES', '200'))
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


@pytest.fixture
def shaper(ros_graph):
    node = ShaperNode(context=ros_graph.context)
    node.sent = []
    node._output.publish = node.sent.append
    yield node
    node.destroy_node()


@FUZZ
@given(messages=st.lists(st.one_of(statuses, commands()), min_size=1, max_size=6))
def test_the_shaper_takes_any_message(shaper, messages):
    limits = shaper.limits
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


# A tick simulates the beam under what it took, so one tick per example.
@settings(FUZZ, max_examples=max(1, CASES // 2))
@given(messages=st.lists(st.one_of(statuses, loads), min_size=1, max_size=6))
def test_the_simulator_takes_any_load_and_estimate(simulator, messages):
    model = simulator.model
    own = model._base_beam.segment_stiffness() / model._base_beam.n_segments
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
