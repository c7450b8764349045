"""The arm demos' graph: who reads what before the first command, and the moves it sends."""

from pathlib import Path

import numpy as np
import pytest

from lumpbeam_ros.apps.demo import arm_graph
from lumpbeam_ros.base.interface import (
    ARM_PARAMS,
    JOINT_STATES,
    JOINT_TRAJECTORY,
    JOINT_TRAJECTORY_SHAPED,
    TIP_POSE,
    TIP_POSE_TRUTH,
)


def test_every_recorded_topic_waits_for_the_probe_the_recorder_and_its_nodes():
    spec = arm_graph.ArmGraph(
        Path('real.yaml'),
        Path('model.yaml'),
        recorded={ARM_PARAMS: 'diagnostic_msgs/msg/DiagnosticArray'},
        readers={ARM_PARAMS: 2},
    )
    readers = spec.subscribers()
    assert set(readers) == set(arm_graph.RECORDED_TOPICS) | {ARM_PARAMS}
    assert readers[TIP_POSE_TRUTH] == readers[arm_graph.REAL_ARM_JOINT_STATES] == 2
    assert readers[JOINT_TRAJECTORY] == 3  # and the shaper
    assert readers[JOINT_TRAJECTORY_SHAPED] == 4  # and both simulators
    assert readers[TIP_POSE] == 4 and readers[JOINT_STATES] == 3
    assert readers[ARM_PARAMS] == 4


@pytest.mark.parametrize(('start', 'end'), [((0.0, 0.0), (0.3, -0.4)), ((0.3, -0.4), (0.8, 1.2))])
def test_a_move_holds_then_ends_exactly_at_its_target_at_rest(start, end):
    move = arm_graph.minimum_jerk(np.array(start), np.array(end), 0.6)
    assert move.time_s[1] == arm_graph.HOLD_S and np.array_equal(move.angles_rad[1], start)
    assert np.array_equal(move.angles_rad[-1], end)  # not start + (end - start)
    assert move.joint_names == ('joint_1', 'joint_2')
    speed = np.diff(move.angles_rad[1:], axis=0) / np.diff(move.time_s[1:])[:, None]
    assert np.abs(speed[[0, -1]]).max() < 1e-3
