"""The nodes' message callbacks fed random messages (the fuzz campaign's live half).

The messages come from a synthetic drop test spoiled by :func:`bagio.helpers.mutate_stream`
(stamps shuffled, duplicated, cut out, jumping up to 1e6 s either way; NaN, inf or 1e308 in
any field; bad or reordered loads), plus random garbage in the values an estimate carries
and in joint trajectories. Each node's callbacks are called as the executor calls them, one
message at a time. What must hold:

- no exception leaves a callback;
- every pose a node was given is kept or counted (in ``/beam_params``' values for the
  identifier, in the buffer's counts and ``non_finite`` for the diagnosis node);
- an identification at level OK is the clean stream's, and never comes from a window with
  more than 5 % of its poses dropped;
- the shaper publishes or counts every trajectory, and its shaper stays finite; the
  simulator keeps a finite, non-negative load.

``make test`` runs a fraction of ``LUMPBEAM_FUZZ_CASES`` (200; ``make fuzz`` runs thousands).
"""

from __future__ import annotations

import math
import os

import numpy as np
import pytest
from builtin_interfaces.msg import Duration
from core.bagio.helpers import mutate_stream, stream_rows
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import PoseStamped
from rclpy.parameter import Parameter
from std_msgs.msg import Float64
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

from lumpbeam_ros.base.interface import BASE_FRAME, IDENTIFIER_STATUS
from lumpbeam_ros.core.model.parameters import load_beam_config
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, write_drop_test_bag
from lumpbeam_ros.nodes.diagnosis_node import DiagnosisNode
from lumpbeam_ros.nodes.identifier_node import IdentifierNode
from lumpbeam_ros.nodes.shaper_node import ShaperNode
from lumpbeam_ros.nodes.simulator_node import SimulatorNode

CASES = int(os.environ.get('LUMPBEAM_FUZZ_CASES', '200'))
NS = 1_000_000_000
OK = 0


@pytest.fixture(scope='module')
def clean_rows(tmp_path_factory):
    """A 5 s drop test's /tip_pose and /tip_load rows."""
    path = tmp_path_factory.mktemp('callbacks') / 'drop'
    beam, drop = load_beam_config()
    write_drop_test_bag(path, beam, drop, SynthOptions(duration_s=5.0, markers_rate_hz=0.0))
    return stream_rows(path)


def _pose(row, frame=BASE_FRAME) -> PoseStamped:
    msg = PoseStamped()
    msg.header.frame_id = frame
    msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(int(row[0]), NS)
    p, q = msg.pose.position, msg.pose.orientation
    p.x, p.y, p.z, q.x, q.y, q.z, q.w = (float(v) for v in row[1:])
    return msg


def _feed(node, poses, loads) -> None:
    """The rows in log order: each load before the first pose stamped after it."""
    pending = sorted(loads, key=lambda row: row[0])
    for row in poses:
        while pending and pending[0][0] <= row[0]:
            node._on_load(Float64(data=float(pending.pop(0)[1])))
        node._on_pose(_pose(row))


def _identify(ros_graph, poses, loads):
    """Feeds an identifier; returns its /beam_params status' level, values and counts."""
    node = IdentifierNode(context=ros_graph.context)
    sent = []
    node._output.publish = sent.append  # what the timer would publish, kept here
    try:
        _feed(node, poses, loads)
        node._on_timer()
        (status,) = sent[-1].status
        return status.level[0], {kv.key: kv.value for kv in status.values}, node.window.counts
    finally:
        node.destroy_node()


def test_identifier_callbacks(ros_graph, clean_rows):
    clean_level, clean_values, _ = _identify(ros_graph, *clean_rows)
    assert clean_level == OK
    clean_hz = float(clean_values['natural_frequency_hz'])
    levels = []
    for seed in range(0, CASES, 10):
        poses, loads = mutate_stream(*clean_rows, seed)
        level, values, counts = _identify(ros_graph, poses, loads)
        levels.append(level)
        assert counts.received == len(poses), f'seed {seed}'
        assert int(values['samples_non_finite']) == counts.non_finite, f'seed {seed}'
        dropped = counts.duplicates + counts.out_of_order
        assert int(values['samples_out_of_order']) == dropped, f'seed {seed}'
        bad_z = sum(1 for row in poses if not math.isfinite(row[3]))
        assert counts.non_finite >= bad_z, f'seed {seed}'
        if level == OK:
            assert not counts.untrusted, f'seed {seed}: OK with {counts}'
            hz = float(values['natural_frequency_hz'])
            assert abs(hz - clean_hz) < 0.05 * clean_hz, f'seed {seed}: {hz} Hz'
    print(f'identifier callbacks: levels {np.bincount(levels, minlength=4).tolist()}')


def test_diagnosis_callbacks(ros_graph, clean_rows):
    for seed in range(1, CASES, 20):
        poses, loads = mutate_stream(*clean_rows, seed)
        node = DiagnosisNode(
            context=ros_graph.context, parameter_overrides=[Parameter('worker', value='thread')]
        )
        try:
            _feed(node, poses, loads)
            measured = node.buffer.measured.counts
            non_finite = node.non_finite  # /tip_pose's; the predicted poses add theirs
            for row in poses[:: max(1, len(poses) // 50)]:
                node._on_predicted(_pose(row))
            bad_z = sum(1 for row in poses if not math.isfinite(row[3]))
            assert non_finite >= bad_z, f'seed {seed}'
            # Every pose is dropped as non-finite here, or given to the buffer, which keeps it
            # or counts it (repeated, out of order).
            assert measured.received + non_finite == len(poses), f'seed {seed}'
            assert measured.kept + measured.dropped == measured.received, f'seed {seed}'
            node.status()
        finally:
            node.destroy_node()


def test_shaper_callbacks(ros_graph):
    rng = np.random.default_rng(7)
    garbage = ['nan', 'inf', '-inf', '-1.0', '0', '1e308', '', 'x', '3.0', '0.02']
    node = ShaperNode(context=ros_graph.context)
    sent = []
    node._output.publish = sent.append
    try:
        given = 0
        for _ in range(max(1, CASES // 4)):
            status = DiagnosticStatus(level=bytes([int(rng.integers(4))]), name=IDENTIFIER_STATUS)
            keys = ('natural_frequency_hz', 'natural_frequency_hz_std', 'damping_ratio',
                    'damping_ratio_std', 'mode_count', 'mode_2_natural_frequency_hz',
                    'mode_2_natural_frequency_hz_std', 'mode_2_damping_ratio',
                    'mode_2_damping_ratio_std')  # fmt: skip
            status.values = [
                KeyValue(key=k, value=str(rng.choice(garbage))) for k in keys if rng.random() < 0.9
            ]
            node._on_params(DiagnosticArray(status=[status]))
            if node.impulses is not None:
                assert np.all(np.isfinite(node.impulses.time_s)), node.description
                assert node.impulses.duration_s <= node.limits.max_added_s, node.description
            msg = JointTrajectory(joint_names=['joint_1'])
            for _ in range(int(rng.integers(0, 6))):
                t = float(rng.choice([rng.uniform(-1, 2), math.nan, math.inf]))
                sec, nanosec = divmod(round(t * NS), NS) if math.isfinite(t) else (0, 0)
                value = float(rng.choice([rng.uniform(-1, 1), math.nan, math.inf]))
                msg.points.append(
                    JointTrajectoryPoint(
                        positions=[value],
                        time_from_start=Duration(sec=int(sec), nanosec=int(nanosec)),
                    )
                )
            node._on_trajectory(msg)
            given += 1
            assert len(sent) + node.dropped == given
    finally:
        node.destroy_node()


def test_simulator_callbacks(ros_graph, clean_rows):
    node = SimulatorNode(context=ros_graph.context)
    rng = np.random.default_rng(11)
    try:
        poses, _ = mutate_stream(*clean_rows, 3)
        for row in poses[::20]:
            node._on_measured(_pose(row))
        for kg in (math.nan, math.inf, -1.0, 1e308, 0.2, 0.0, float(rng.uniform(0, 1))):
            node.model._on_load(Float64(data=kg))
            assert math.isfinite(node.model._load_kg) and node.model._load_kg >= 0.0
        status = DiagnosticStatus(level=bytes([OK]), name=IDENTIFIER_STATUS)
        for value in ('nan', 'inf', '-5', '1e308', 'x', ''):
            status.values = [
                KeyValue(key='stiffness_total_nm_per_rad', value=value),
                KeyValue(key='damping_ratio', value=value),
            ]
            node.model._on_beam_params(DiagnosticArray(status=[status]))
    finally:
        node.destroy_node()
