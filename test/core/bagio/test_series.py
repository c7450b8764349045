import numpy as np
import pytest

from lumpbeam_ros.base.errors import BagError
from lumpbeam_ros.core.bagio import (
    BagReader,
    BagWriter,
    CameraInfoData,
    Status,
    TipSeries,
    iter_images,
    read_camera_info,
    read_diagnostics,
    read_load_events,
    read_points,
    read_tip_poses,
)

from .helpers import T0, write_drop_bag


def test_poses_and_load_round_trip(tmp_path):
    s = write_drop_bag(tmp_path / 'drop', images=3)
    poses = read_tip_poses(tmp_path / 'drop')
    assert poses.frame_id == 'beam_base'
    np.testing.assert_allclose(poses.t - T0, s['t'], atol=1e-6)
    np.testing.assert_array_equal(poses.z, s['z'])
    np.testing.assert_allclose(poses.pitch, s['pitch'], atol=1e-15)
    load = read_load_events(tmp_path / 'drop').changes()
    np.testing.assert_array_equal(load.kg, [4.5, 0.0])
    assert load.t[1] - T0 == pytest.approx(2.0, abs=0.1)
    frames = list(iter_images(tmp_path / 'drop'))
    assert [int(f.pixels[0, 0]) for f in frames] == [0, 1, 2]
    assert frames[1].pixels.shape == (8, 10) and frames[1].encoding == 'mono8'


def test_poses_are_a_tip_series_sorted_by_stamp(tmp_path):
    with BagWriter(tmp_path / 'b') as bag:
        for t in (3.0, 1.0, 2.0):  # written out of order, e.g. late camera frames
            bag.write_pose('/tip_pose', t, 1.0, -t, 0.0, frame='world')
    poses = read_tip_poses(tmp_path / 'b')
    assert isinstance(poses, TipSeries) and len(poses) == 3
    np.testing.assert_array_equal(poses.t, [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(poses.z, [-1.0, -2.0, -3.0])
    assert poses.frame_id == 'world'


def test_mixed_frames_are_an_error(tmp_path):
    with BagWriter(tmp_path / 'b') as bag:
        bag.write_pose('/tip_pose', 1.0, 1.0, 0.0, 0.0, frame='beam_base')
        bag.write_pose('/tip_pose', 2.0, 1.0, 0.0, 0.0, frame='camera')
    with pytest.raises(BagError, match='mixes frames'):
        read_tip_poses(tmp_path / 'b')


def test_points_camera_info_and_diagnostics(tmp_path):
    k = np.array([[800.0, 0, 320], [0, 800.0, 240], [0, 0, 1]])
    status = Status('lumpbeam/identifier', 0, 'ok', {'natural_frequency_hz': repr(3.1)})
    with BagWriter(tmp_path / 'b') as bag:
        bag.write_point('/tracker/point', 1.5, 2.3, 0.0, -0.01, 'tracker')
        bag.write_camera_info('/camera/camera_info', 1.0, CameraInfoData(640, 480, k))
        bag.write_diagnostics('/beam_params', 2.0, [status])
        bag.write_clock(2.0)
    points = read_points(tmp_path / 'b')
    assert (points.t[0], points.x[0], points.z[0], points.frame_id) == (1.5, 2.3, -0.01, 'tracker')
    np.testing.assert_array_equal(read_camera_info(tmp_path / 'b').k, k)
    [(stamp, statuses)] = read_diagnostics(tmp_path / 'b')
    assert stamp == 2.0 and statuses == [status]
    assert BagReader(tmp_path / 'b').topics['/clock'].msgtype == 'rosgraph_msgs/msg/Clock'


def test_missing_and_mistyped_topics_are_errors(tmp_path):
    write_drop_bag(tmp_path / 'drop')
    with pytest.raises(
        BagError, match=r'no topic /camera/image_raw \(topics: /tip_load, /tip_pose\)'
    ):
        list(iter_images(tmp_path / 'drop'))
    with pytest.raises(BagError, match='has type geometry_msgs/msg/PoseStamped, not std_msgs'):
        read_load_events(tmp_path / 'drop', topic='/tip_pose')
    with pytest.raises(BagError, match='no message'):
        with BagWriter(tmp_path / 'empty') as bag:
            bag.add_topic('/camera/camera_info', 'sensor_msgs/msg/CameraInfo')
        read_camera_info(tmp_path / 'empty')


def test_joint_states_round_trip_and_other_joints_are_an_error(tmp_path):
    from lumpbeam_ros.core.bagio import BagWriter
    from lumpbeam_ros.core.bagio.series import read_joint_states

    with BagWriter(tmp_path / 'arm') as bag:
        for k in (2, 0, 1):  # written out of order: read sorted
            bag.write_joint_state('/joint_states', 1.0 + k, ('a', 'b'), np.array([k, -k]))
    series = read_joint_states(tmp_path / 'arm')
    assert series.t.tolist() == [1.0, 2.0, 3.0] and series.names == ('a', 'b')
    assert series.angles.tolist() == [[0, 0], [1, -1], [2, -2]]
    with BagWriter(tmp_path / 'mixed') as bag:
        bag.write_joint_state('/joint_states', 1.0, ('a', 'b'), np.array([0.0, 0.0]))
        bag.write_joint_state('/joint_states', 2.0, ('a',), np.array([0.0]))
    with pytest.raises(BagError, match=r"names joints \['a'\] with 1 positions after"):
        read_joint_states(tmp_path / 'mixed')
    with pytest.raises(BagError, match='no topic /joint_states'):
        read_joint_states(tmp_path / 'arm', '/joint_states_other')


def test_a_joint_state_recorded_twice_counts_once(tmp_path):
    from lumpbeam_ros.core.bagio import BagWriter
    from lumpbeam_ros.core.bagio.series import read_joint_states

    with BagWriter(tmp_path / 'twice') as bag:
        for stamp, angle in ((0.0, 0.0), (0.1, 0.2), (0.1, 0.3), (0.2, 0.2)):
            bag.write_joint_state('/joint_states', stamp, ['joint_1'], np.array([angle]))
    series = read_joint_states(tmp_path / 'twice')
    assert series.t == pytest.approx([0.0, 0.1, 0.2])
    assert series.angles[:, 0].tolist() == [0.0, 0.2, 0.2]  # the first copy of 0.1 s
