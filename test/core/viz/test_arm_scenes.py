"""A recorded arm's markers: the model along the bag's joint states, beside its tip."""

import numpy as np
import pytest
from arm_cases import small_arm

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.bagio import BagReader, BagWriter, read_tip_poses
from lumpbeam_ros.core.bagio.typestore import deserialize
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.synthetic.arm_bag import ArmSynthOptions, write_arm_bag
from lumpbeam_ros.core.viz.arm_scenes import recorded_arm_markers


@pytest.fixture(scope='module')
def bag(tmp_path_factory):
    """A two-link arm's bag as a real arm records it: joint states and tip poses only."""
    path = tmp_path_factory.mktemp('recorded') / 'arm'
    t = np.arange(0.0, 0.3 + 1e-9, 0.01)
    move = JointTrajectory(t, np.outer(t, [1.0, -1.0]))
    write_arm_bag(path, small_arm(2), move, ArmSynthOptions(duration_s=0.6, markers_rate_hz=0))
    return path


def test_the_model_is_drawn_along_the_joint_states_beside_the_measured_tip(bag):
    reader = BagReader(bag)
    assert '/beam_markers' not in reader.topics
    arrays = recorded_arm_markers(reader, small_arm(2))
    stamps = np.array([a.log_time_ns for a in arrays]) / 1e9
    assert stamps.size == 19 and np.allclose(np.diff(stamps), 1 / 30, atol=6e-3)  # 0.6 s
    truth = read_tip_poses(bag, '/tip_pose_truth')
    for raw, stamp in zip(arrays, stamps, strict=True):
        markers = deserialize(raw.data, raw.msgtype).markers
        links = [m for m in markers if m.ns == 'arm_link']
        assert [len(m.points) for m in links] == [5, 4]
        predicted = next(m for m in markers if m.ns == 'tip_predicted').pose.position
        i = int(np.argmin(np.abs(truth.t - stamp)))
        # The model follows the recorded 180 Hz angles, the truth the 100 Hz file's lines.
        assert abs(predicted.z - truth.z[i]) < 1e-3 and abs(predicted.x - truth.x[i]) < 1e-3
        assert links[-1].points[-1].z == pytest.approx(predicted.z)
        assert any(m.ns == 'tip_measured' for m in markers)


def test_an_arm_with_other_joints_is_one_clear_error(bag):
    with pytest.raises(LumpbeamError, match="the arm has \\['joint_1', 'joint_2', 'joint_3'\\]"):
        recorded_arm_markers(BagReader(bag), small_arm(3))


def test_a_bag_without_joint_states_is_one_clear_error(tmp_path):
    with BagWriter(tmp_path / 'poses') as writer:
        writer.write_pose('/tip_pose', 1.0, 2.3, -0.05, 0.02)
    with pytest.raises(LumpbeamError, match='no /joint_states'):
        recorded_arm_markers(BagReader(tmp_path / 'poses'), small_arm(2))
