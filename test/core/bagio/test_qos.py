"""QoS profiles: the project's choices per topic, and metadata entries read back."""

import pytest
from rosbags.interfaces import QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime
from rosbags.rosbag2.metadata import dump_qos_v9

from lumpbeam_ros.core.bagio.qos import (
    SENSOR_DEPTH,
    STREAM_DEPTH,
    default_profile,
    from_dict,
    profile,
)


@pytest.mark.parametrize(
    ('topic', 'msgtype', 'reliability', 'durability', 'depth'),
    [
        ('/camera/image_raw', 'sensor_msgs/msg/Image', 'BEST_EFFORT', 'VOLATILE', SENSOR_DEPTH),
        (
            '/camera/camera_info',
            'sensor_msgs/msg/CameraInfo',
            'BEST_EFFORT',
            'VOLATILE',
            SENSOR_DEPTH,
        ),
        ('/tip_load', 'std_msgs/msg/Float64', 'RELIABLE', 'TRANSIENT_LOCAL', 1),
        ('/tip_pose', 'geometry_msgs/msg/PoseStamped', 'RELIABLE', 'VOLATILE', STREAM_DEPTH),
        (
            '/beam_params',
            'diagnostic_msgs/msg/DiagnosticArray',
            'RELIABLE',
            'VOLATILE',
            STREAM_DEPTH,
        ),
    ],
)
def test_default_profiles(topic, msgtype, reliability, durability, depth):
    qos = default_profile(topic, msgtype)
    assert qos.reliability is QosReliability[reliability]
    assert qos.durability is QosDurability[durability]
    assert (qos.history, qos.depth) == (QosHistory.KEEP_LAST, depth)
    # 400 poses at 180 Hz: more than the second a descheduled subscriber may miss.
    assert STREAM_DEPTH / 180.0 > 2.0


@pytest.mark.parametrize('reliable', [True, False])
@pytest.mark.parametrize('transient_local', [True, False])
def test_profiles_round_trip_through_rosbags_metadata_writer(reliable, transient_local):
    qos = profile(reliable, transient_local, depth=7)
    (entry,) = dump_qos_v9([qos])  # what rosbags writes into metadata.yaml
    assert from_dict(entry) == qos


def test_an_entry_as_ros2_bag_record_writes_it():
    entry = {
        'history': 'unknown',
        'depth': 0,
        'reliability': 'reliable',
        'durability': 'transient_local',
        'deadline': {'sec': 9223372036, 'nsec': 854775807},
        'lifespan': {'sec': 9223372036, 'nsec': 854775807},
        'liveliness': 'automatic',
        'liveliness_lease_duration': {'sec': 9223372036, 'nsec': 854775807},
        'avoid_ros_namespace_conventions': False,
    }
    qos = from_dict(entry)
    assert qos.history is QosHistory.UNKNOWN
    assert qos.reliability is QosReliability.RELIABLE
    assert qos.durability is QosDurability.TRANSIENT_LOCAL
    assert qos.liveliness is QosLiveliness.AUTOMATIC
    assert qos.deadline == QosTime(9223372036, 854775807)


def test_missing_and_unknown_policies():
    qos = from_dict({'reliability': 'sometimes'})
    assert qos.reliability is QosReliability.UNKNOWN
    assert qos.history is QosHistory.SYSTEM_DEFAULT
    assert qos.durability is QosDurability.SYSTEM_DEFAULT
    assert (qos.depth, qos.deadline, qos.avoid_ros_namespace_conventions) == (
        0,
        QosTime(0, 0),
        False,
    )
