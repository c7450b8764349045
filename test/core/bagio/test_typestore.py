"""The typestore: message classes, descriptions, (de)serialization and their errors.

The same typestore against ROS 2 itself (its generated hashes, fields and serializer) is
``test/nodes/test_typestore_ros.py``.
"""

import numpy as np
import pytest

from lumpbeam_ros.base.errors import BagError
from lumpbeam_ros.core.bagio.typestore import (
    deserialize,
    is_known,
    message_class,
    prepare,
    serialize,
    type_description,
    typestore,
)

#: The types the product writes and reads.

PRODUCT_TYPES = [
    'diagnostic_msgs/msg/DiagnosticArray',
    'geometry_msgs/msg/PointStamped',
    'geometry_msgs/msg/PoseStamped',
    'geometry_msgs/msg/PoseWithCovarianceStamped',
    'rosgraph_msgs/msg/Clock',
    'sensor_msgs/msg/CameraInfo',
    'sensor_msgs/msg/CompressedImage',
    'sensor_msgs/msg/Image',
    'std_msgs/msg/Float64',
    'visualization_msgs/msg/MarkerArray',
]


@pytest.mark.parametrize(
    ('msgtype', 'known'),
    [
        ('std_msgs/msg/Float64', True),
        ('sensor_msgs/msg/Image', True),
        ('std_msgs/msg/Float65', False),
        ('std_msgs/Float64', False),  # ROS 1 spelling
        ('my_pkg/msg/Thing', False),
        ('', False),
    ],
)
def test_is_known(msgtype, known):
    assert is_known(msgtype) is known


def test_message_class_builds_messages_of_its_type():
    pose = message_class('geometry_msgs/msg/Point')(x=1.0, y=2.0, z=3.0)
    assert pose.__msgtype__ == 'geometry_msgs/msg/Point' and (pose.x, pose.z) == (1.0, 3.0)


def test_prepare_generates_the_code_of_a_type_and_of_the_types_it_nests():
    prepare(['sensor_msgs/msg/Image'])
    assert {'sensor_msgs/msg/Image', 'std_msgs/msg/Header'} <= set(typestore().cache)


@pytest.mark.parametrize(
    'call',
    [message_class, type_description, lambda t: deserialize(b'', t), lambda t: prepare([t])],
)
@pytest.mark.parametrize('msgtype', ['my_pkg/msg/Thing', 'std_msgs/Float64'])
def test_an_unknown_type_is_one_clear_error(call, msgtype):
    match = rf"unknown message type '{msgtype}' \(not in ROS 2 Jazzy\)"
    with pytest.raises(BagError, match=match):
        call(msgtype)


def test_deserialize_accepts_a_memoryview():
    data = serialize(message_class('std_msgs/msg/Float64')(data=2.5))
    assert data == b'\0\1\0\0' + np.float64(2.5).tobytes()  # CDR little-endian header
    assert deserialize(memoryview(data), 'std_msgs/msg/Float64').data == 2.5
