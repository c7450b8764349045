"""QoS profiles as bags store them (ROS-free, rosbags' :class:`~rosbags.interfaces.Qos`).

A bag keeps each topic's offered QoS so that a player can offer the same again. The project's
defaults, used for synthetic bags and by the player when a bag has none:

- images and camera info: best effort, volatile, keep last :data:`SENSOR_DEPTH`: a late
  frame is worth less than the next one and must never stall a 180 fps stream, but a
  reader's history must cover the moments its process is off the CPU;
- ``/tip_load`` and ``/arm_params``: reliable, transient local, keep last 1. They change
  rarely (a drop, a ring-down fitted), so a node that starts after the last change still
  needs the current value; a transient-local publisher also serves volatile subscribers,
  so nobody is excluded;
- everything else (poses, ``/beam_params``, ``/clock``): reliable, volatile, keep last
  :data:`STREAM_DEPTH`. Nothing of these may be lost: a reliable keep-last writer drops its
  oldest sample for a reader that has not acknowledged it once the history is full, and a
  reader's history drops its oldest sample when its executor falls behind, so the depth is
  the stall either side can absorb.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from rosbags.interfaces import (
    Qos,
    QosDurability,
    QosHistory,
    QosLiveliness,
    QosReliability,
    QosTime,
)

from lumpbeam_ros.base.interface import ARM_PARAMS, CAMERA_INFO_TYPE, IMAGE_TYPE, TIP_LOAD

#: How rosbag2 writes an infinite duration (``RMW_DURATION_INFINITE``).
INFINITE = QosTime(2147483647, 4294967295)
ZERO = QosTime(0, 0)

#: History of the reliable streams: 400 samples are 2.2 s of 180 Hz poses. A second of data
#: (180) covers a subscriber whose process is off the CPU for a second on a loaded core;
#: the margin covers bursts (the simulator publishes the samples of a late tick at once, the
#: player publishes ``/clock`` beside every message, doubling the rate). A PoseStamped is
#: about 100 bytes, so a history costs some 40 kB per endpoint.
STREAM_DEPTH = 400
#: History of the sensor-data profile (images, camera info): a third of a second at 180 fps.
#: ROS's sensor-data profile keeps 5, 28 ms at 180 fps: with two busy loops on two cores
#: the camera node, off the CPU for longer than that, lost up to a fifth of the frames
#: (doc/validation.md, 'Speed'). A reader's history holds frames only while it is behind;
#: full, it is 60 MB of 1024 x 1024 mono8 frames.
SENSOR_DEPTH = 60

SENSOR_TYPES = (IMAGE_TYPE, CAMERA_INFO_TYPE)
LATCHED_TOPICS = (TIP_LOAD, ARM_PARAMS)


def profile(reliable: bool, transient_local: bool, depth: int) -> Qos:
    """Builds a keep-last profile with the other policies at their defaults.

    Args:
        reliable: Reliable (else best effort).
        transient_local: Transient local (else volatile).
        depth: History depth.

    Returns:
        The profile.
    """
    return Qos(
        history=QosHistory.KEEP_LAST,
        depth=depth,
        reliability=QosReliability.RELIABLE if reliable else QosReliability.BEST_EFFORT,
        durability=QosDurability.TRANSIENT_LOCAL if transient_local else QosDurability.VOLATILE,
        deadline=INFINITE,
        lifespan=INFINITE,
        liveliness=QosLiveliness.AUTOMATIC,
        liveliness_lease_duration=INFINITE,
        avoid_ros_namespace_conventions=False,
    )


def default_profile(topic: str, msgtype: str) -> Qos:
    """Returns the project's profile for a topic (see the module docstring)."""
    if msgtype in SENSOR_TYPES:
        return profile(reliable=False, transient_local=False, depth=SENSOR_DEPTH)
    if topic in LATCHED_TOPICS:
        return profile(reliable=True, transient_local=True, depth=1)
    return profile(reliable=True, transient_local=False, depth=STREAM_DEPTH)


def from_dict(entry: Mapping[str, Any]) -> Qos:
    """Parses one offered profile as ``metadata.yaml`` (version 9) lists it.

    Args:
        entry: E.g. ``{'history': 'keep_last', 'depth': 10, 'reliability': 'reliable', ...}``.

    Returns:
        The profile; unknown or missing policies become ``SYSTEM_DEFAULT``/``UNKNOWN``.
    """

    def enum(kind: Any, key: str) -> Any:
        name = str(entry.get(key, 'system_default')).upper()
        return kind[name] if name in kind.__members__ else kind['UNKNOWN']

    def duration(key: str) -> QosTime:
        value = entry.get(key) or {}
        return QosTime(int(value.get('sec', 0)), int(value.get('nsec', 0)))

    return Qos(
        history=enum(QosHistory, 'history'),
        depth=int(entry.get('depth', 0)),
        reliability=enum(QosReliability, 'reliability'),
        durability=enum(QosDurability, 'durability'),
        deadline=duration('deadline'),
        lifespan=duration('lifespan'),
        liveliness=enum(QosLiveliness, 'liveliness'),
        liveliness_lease_duration=duration('liveliness_lease_duration'),
        avoid_ros_namespace_conventions=bool(entry.get('avoid_ros_namespace_conventions')),
    )
