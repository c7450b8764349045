from datetime import datetime, timezone
from pathlib import Path

import numpy as np
import pytest

from lumpbeam_ros.base.errors import RecordError
from lumpbeam_ros.base.interface import TIP_IMU, TIP_POSE
from lumpbeam_ros.core.bagio import BagReader, read_accelerations, read_tip_poses
from lumpbeam_ros.core.records.labfile import LabRecord
from lumpbeam_ros.core.records.to_bag import ImportOptions, write_record_bag
from lumpbeam_ros.core.records.units import STANDARD_GRAVITY

START_S = 946684800.0  # 2000-01-01T00:00:00Z


def _record(values, rate_hz=1000.0) -> LabRecord:
    values = np.asarray(values, float)
    return LabRecord(np.arange(values.size) / rate_hz, values, 'acc', Path('r.csv'))


def test_an_acceleration_in_g_becomes_tip_imu_in_si_along_its_axis(tmp_path):
    summary = write_record_bag(
        _record([0.5, -1.0, 2.0]), tmp_path / 'b', ImportOptions('acceleration', 'g', axis='y')
    )
    assert (summary.topic, summary.messages, summary.gaps) == (TIP_IMU, 3, 0)
    series = read_accelerations(tmp_path / 'b')
    assert series.frame_id == 'tip'
    np.testing.assert_allclose(series.y, np.array([0.5, -1.0, 2.0]) * STANDARD_GRAVITY)
    np.testing.assert_array_equal(series.x, 0.0)
    np.testing.assert_allclose(series.t - START_S, [0.0, 1e-3, 2e-3], atol=1e-6)
    # Orientation and angular velocity are marked unknown, as sensor_msgs/Imu asks.
    _, message = next(iter(BagReader(tmp_path / 'b').messages(TIP_IMU, 'sensor_msgs/msg/Imu')))
    assert message.orientation_covariance[0] == -1.0
    assert message.angular_velocity_covariance[0] == -1.0


def test_a_displacement_in_mm_becomes_tip_pose_and_its_gaps_are_left_out(tmp_path):
    options = ImportOptions('displacement', 'mm', start='2026-11-29T12:00:00+01:00')
    summary = write_record_bag(_record([1.0, np.nan, 3.0]), tmp_path / 'b', options)
    assert (summary.topic, summary.messages, summary.gaps) == (TIP_POSE, 2, 1)
    poses = read_tip_poses(tmp_path / 'b')
    np.testing.assert_allclose(poses.z, [1e-3, 3e-3])
    assert poses.frame_id == 'beam_base' and np.all(poses.pitch == 0.0)
    eleven_utc = datetime(2026, 11, 29, 11, tzinfo=timezone.utc).timestamp()
    assert poses.t[0] == pytest.approx(eleven_utc) and summary.start_s == pytest.approx(eleven_utc)


def test_stamps_are_whole_nanoseconds_of_the_record_time(tmp_path):
    write_record_bag(
        _record(np.ones(5), rate_hz=3.0), tmp_path / 'b', ImportOptions('displacement')
    )
    stamps = [
        ns
        for ns, _ in BagReader(tmp_path / 'b').messages(TIP_POSE, 'geometry_msgs/msg/PoseStamped')
    ]
    assert [s - stamps[0] for s in stamps] == [0, 333333333, 666666667, 1000000000, 1333333333]


@pytest.mark.parametrize(
    ('options', 'message'),
    [
        (ImportOptions('velocity'), "unknown quantity 'velocity'"),
        (
            ImportOptions('acceleration', 'mm'),
            "unit 'mm' is not one of a acceleration: m/s\\^2, g",
        ),
        (ImportOptions('displacement', axis='w'), "unknown axis 'w'"),
        (ImportOptions('displacement', start='yesterday'), 'not an ISO 8601 time'),
        (ImportOptions('displacement', start='1960-01-01T00:00:00Z'), 'before 1970'),
    ],
)
def test_bad_options_are_refused_before_a_bag_is_made(tmp_path, options, message):
    with pytest.raises(RecordError, match=message):
        write_record_bag(_record([1.0, 2.0]), tmp_path / 'b', options)
    assert not (tmp_path / 'b').exists()


def test_a_record_time_beyond_a_ros_stamp_is_refused(tmp_path):
    record = LabRecord(np.array([0.0, 3e9]), np.ones(2), 'acc', Path('r.csv'))
    with pytest.raises(RecordError, match='does not fit a ROS stamp'):
        write_record_bag(record, tmp_path / 'b', ImportOptions('displacement'))
