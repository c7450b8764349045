"""ROS message classes and QoS profiles from their names, for the generic recorder and player.

``rosidl_runtime_py`` (whose ``get_message`` does this) is not among the PyPI wheels of ROS 2
Jazzy, so a type ``pkg/msg/Name`` is imported as ``pkg.msg.Name``.
"""

from __future__ import annotations

import importlib
from typing import Any

from rclpy.duration import Duration
from rclpy.qos import (
    DurabilityPolicy,
    HistoryPolicy,
    LivelinessPolicy,
    QoSProfile,
    ReliabilityPolicy,
)
from rosbags.interfaces import (
    Qos,
    QosDurability,
    QosHistory,
    QosLiveliness,
    QosReliability,
    QosTime,
)

from lumpbeam_ros.base.errors import BagError
from lumpbeam_ros.base.interface import TOPIC_TYPES
from lumpbeam_ros.core.bagio.qos import INFINITE, SENSOR_DEPTH, STREAM_DEPTH, default_profile

_MAX_SEC = 2**31 - 1


def message_class(msgtype: str) -> type[Any]:
    """Imports the rclpy message class of ``'pkg/msg/Name'``.

    Raises:
        BagError: A malformed name or a type this ROS installation lacks.
    """
    parts = msgtype.split('/')
    if len(parts) != 3 or parts[1] != 'msg':
        raise BagError(f'not a ROS 2 message type name: {msgtype!r}')
    try:
        return getattr(importlib.import_module(f'{parts[0]}.msg'), parts[2])
    except (ImportError, AttributeError):
        raise BagError(f'message type {msgtype} is not installed in this ROS 2') from None


def _time(duration: Duration) -> QosTime:
    sec, nsec = divmod(duration.nanoseconds, 1_000_000_000)
    return INFINITE if sec >= _MAX_SEC else QosTime(sec, nsec)


def to_bag_qos(profile: QoSProfile) -> Qos:
    """Converts an rclpy profile (e.g. a publisher's, from the graph) to the bag's form."""
    # rclpy's and rosbags' enums both mirror rmw's values.
    return Qos(
        history=QosHistory(int(profile.history)),
        depth=int(profile.depth),
        reliability=QosReliability(int(profile.reliability)),
        durability=QosDurability(int(profile.durability)),
        deadline=_time(profile.deadline),
        lifespan=_time(profile.lifespan),
        liveliness=QosLiveliness(int(profile.liveliness)),
        liveliness_lease_duration=_time(profile.liveliness_lease_duration),
        avoid_ros_namespace_conventions=bool(profile.avoid_ros_namespace_conventions),
    )


def from_bag_qos(qos: Qos) -> QoSProfile:
    """Converts a bag's offered profile to an rclpy profile for a publisher.

    Only history, depth, reliability and durability are carried over: they decide which
    subscribers match; the other policies keep rclpy's defaults.
    """
    keep_all = qos.history == QosHistory.KEEP_ALL
    best_effort = qos.reliability == QosReliability.BEST_EFFORT
    return QoSProfile(
        history=HistoryPolicy.KEEP_ALL if keep_all else HistoryPolicy.KEEP_LAST,
        # Graph discovery reports history UNKNOWN and depth 0 for remote publishers.
        depth=int(qos.depth) if qos.depth > 0 else SENSOR_DEPTH if best_effort else STREAM_DEPTH,
        reliability=ReliabilityPolicy.BEST_EFFORT if best_effort else ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL
        if qos.durability == QosDurability.TRANSIENT_LOCAL
        else DurabilityPolicy.VOLATILE,
        liveliness=LivelinessPolicy.AUTOMATIC,
    )


def topic_qos(topic: str, msgtype: str | None = None) -> QoSProfile:
    """The project's profile of a topic (:func:`~lumpbeam_ros.core.bagio.qos.default_profile`).

    Every node's publishers and subscriptions take their profile from here, so both ends of
    a topic always agree. Each call builds a new profile (a QoS override changes it in place).

    Args:
        topic: The interface's (absolute) topic name, e.g. ``'/tip_pose'``.
        msgtype: Its type; ``None``: the interface's
            (:data:`~lumpbeam_ros.base.interface.TOPIC_TYPES`).

    Returns:
        The rclpy profile.
    """
    return from_bag_qos(default_profile(topic, msgtype or TOPIC_TYPES[topic]))
