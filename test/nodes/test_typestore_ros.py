"""The typestore against ROS 2 itself: its generated hashes, fields and serializer."""

import importlib
import json
import os
import sys
from pathlib import Path

import numpy as np
import pytest
from core.bagio.test_typestore import PRODUCT_TYPES

from lumpbeam_ros.base.errors import BagError
from lumpbeam_ros.core.bagio.typestore import (
    deserialize,
    serialize,
    type_description,
)

#: The types the product writes and reads.


def _ros_class(msgtype):
    """The message class that ROS 2's own generator made (rclpy's message packages)."""
    package, _, name = msgtype.split('/')
    return getattr(importlib.import_module(f'{package}.msg'), name)


def _ros_type_hash(msgtype):
    """The RIHS01 hash that rosidl wrote beside the message's definition at build time."""
    package, _, name = msgtype.split('/')
    prefixes = [sys.prefix, *filter(None, os.environ.get('AMENT_PREFIX_PATH', '').split(':'))]
    for prefix in prefixes:
        path = Path(prefix, 'share', package, 'msg', f'{name}.json')
        if path.is_file():
            hashes = json.loads(path.read_text())['type_hashes']
            return next(h['hash_string'] for h in hashes if h['type_name'] == msgtype)
    pytest.skip(f'ROS 2 does not describe {msgtype} here')


@pytest.mark.parametrize('msgtype', PRODUCT_TYPES)
def test_the_type_hash_is_the_one_ros_generates(msgtype):
    assert type_description(msgtype)[1] == _ros_type_hash(msgtype)


@pytest.mark.parametrize('msgtype', PRODUCT_TYPES)
def test_the_definition_lists_the_fields_ros_has(msgtype):
    msgdef, _ = type_description(msgtype)
    own = msgdef.split('=' * 80)[0]  # the type itself; its dependencies follow after MSG:
    fields = [
        line.split()[1]
        for line in own.splitlines()
        if line.strip() and not line.startswith('#') and '=' not in line.split()[1]
    ]
    assert fields == list(_ros_class(msgtype).get_fields_and_field_types())
    dependencies = [line[5:] for line in msgdef.splitlines() if line.startswith('MSG: ')]
    assert len(dependencies) == len(set(dependencies))  # each one once, as ros2 bag stores it


def _ros_pose():
    msg = _ros_class('geometry_msgs/msg/PoseStamped')()
    msg.header.stamp.sec, msg.header.stamp.nanosec = 1_700_000_000, 123_456_789
    msg.header.frame_id = 'beam_base'
    msg.pose.position.x, msg.pose.position.z = 2.31, -0.05
    msg.pose.orientation.y, msg.pose.orientation.w = -0.0162, 0.99987
    return msg


def _ros_image():
    msg = _ros_class('sensor_msgs/msg/Image')()
    msg.height, msg.width, msg.encoding, msg.step = 3, 5, 'mono8', 5
    msg.data = bytes(range(15))
    return msg


def _ros_float():
    return _ros_class('std_msgs/msg/Float64')(data=-4.5e-3)


@pytest.mark.parametrize('make', [_ros_pose, _ros_image, _ros_float])
def test_cdr_is_what_rclpy_reads_and_writes(make):
    from rclpy.serialization import deserialize_message, serialize_message

    ros = make()
    data = serialize_message(ros)
    msgtype = type(ros).__module__.split('.')[0] + '/msg/' + type(ros).__name__
    ours = deserialize(data, msgtype)
    for name in _ros_class(msgtype).get_fields_and_field_types():
        mine, theirs = getattr(ours, name), getattr(ros, name)
        if hasattr(theirs, 'get_fields_and_field_types'):
            theirs = deserialize(serialize_message(theirs), mine.__msgtype__)
            assert mine == theirs, name
        else:
            assert np.array_equal(np.asarray(mine), np.asarray(theirs)), name
    # The padding bytes rclpy leaves uninitialised: the same length, the same message.
    back = serialize(ours)
    assert len(back) == len(data)
    assert deserialize_message(back, type(ros)) == ros


@pytest.mark.parametrize(
    ('cut', 'msgtype'),
    [
        (slice(0, 0), 'std_msgs/msg/Float64'),
        (slice(0, 6), 'std_msgs/msg/Float64'),
        (slice(0, 20), 'geometry_msgs/msg/PoseStamped'),
        (slice(0, -9), 'geometry_msgs/msg/PoseStamped'),
    ],
)
def test_bytes_that_are_not_the_message_are_a_clear_error(cut, msgtype):
    from rclpy.serialization import serialize_message

    data = serialize_message(_ros_class(msgtype)())[cut]
    with pytest.raises(BagError, match=rf'corrupt {msgtype} message \({len(data)} bytes\)'):
        deserialize(data, msgtype)


def test_a_string_longer_than_its_message_is_a_clear_error():
    from rclpy.serialization import serialize_message

    # frame_id's length field claims 1000 bytes that the message does not have.
    data = bytearray(serialize_message(_ros_class('std_msgs/msg/Header')(frame_id='beam_base')))
    data[12:16] = (1000).to_bytes(4, 'little')
    with pytest.raises(BagError, match='corrupt std_msgs/msg/Header message'):
        deserialize(bytes(data), 'std_msgs/msg/Header')
