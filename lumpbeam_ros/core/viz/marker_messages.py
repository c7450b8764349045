"""Markers as ``visualization_msgs/msg/MarkerArray`` messages, and back (no ROS needed).

The rosbags class is used both for bags and, as its CDR bytes, by the simulator node
(rclpy publishes serialized bytes as they are), so the node and the bags carry the same
bytes for the same markers.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from lumpbeam_ros.base.interface import COMPRESSED_IMAGE_TYPE, MARKER_ARRAY
from lumpbeam_ros.core.bagio import BagReader, BagWriter, convert
from lumpbeam_ros.core.bagio.typestore import message_class, serialize
from lumpbeam_ros.core.viz.markers import (
    FRAME_ID,
    MARKERS_TOPIC,
    Action,
    BeamScene,
    MarkerSpec,
    Shape,
    scene_markers,
)

MARKER_ARRAY_TYPE = MARKER_ARRAY


def _duration(seconds: float) -> Any:
    sec, nanosec = divmod(convert.seconds_to_ns(seconds), convert.NS_PER_S)
    return message_class('builtin_interfaces/msg/Duration')(sec=int(sec), nanosec=int(nanosec))


def marker_message(spec: MarkerSpec, stamp_ns: int, frame_id: str = FRAME_ID) -> Any:
    """Builds one ``visualization_msgs/msg/Marker``.

    Args:
        spec: The marker.
        stamp_ns: Header stamp, ns.
        frame_id: Header frame.

    Returns:
        The rosbags message.
    """
    point = message_class('geometry_msgs/msg/Point')
    quaternion = message_class('geometry_msgs/msg/Quaternion')
    color = message_class('std_msgs/msg/ColorRGBA')
    r, g, b, a = (float(v) for v in spec.color)
    pose = message_class('geometry_msgs/msg/Pose')(
        position=point(*(float(v) for v in spec.position)),
        orientation=quaternion(*(float(v) for v in spec.orientation)),
    )
    return message_class('visualization_msgs/msg/Marker')(
        header=convert.header(stamp_ns, frame_id),
        ns=spec.namespace,
        id=int(spec.marker_id),
        type=int(spec.shape),
        action=int(spec.action),
        pose=pose,
        scale=message_class('geometry_msgs/msg/Vector3')(*(float(v) for v in spec.scale)),
        color=color(r=r, g=g, b=b, a=a),
        lifetime=_duration(spec.lifetime_s),
        frame_locked=False,
        points=[point(*(float(v) for v in p)) for p in spec.points],
        colors=[],
        texture_resource='',
        texture=message_class(COMPRESSED_IMAGE_TYPE)(
            header=convert.header(0, ''), format='', data=np.empty(0, dtype=np.uint8)
        ),
        uv_coordinates=[],
        text='',
        mesh_resource='',
        mesh_file=message_class('visualization_msgs/msg/MeshFile')(
            filename='', data=np.empty(0, dtype=np.uint8)
        ),
        mesh_use_embedded_materials=False,
    )


def marker_array(markers: Sequence[MarkerSpec], stamp_ns: int, frame_id: str = FRAME_ID) -> Any:
    """Builds a ``visualization_msgs/msg/MarkerArray`` of markers all stamped ``stamp_ns``."""
    return message_class(MARKER_ARRAY_TYPE)(
        markers=[marker_message(m, stamp_ns, frame_id) for m in markers]
    )


def scene_cdr(scene: BeamScene, stamp_ns: int, lifetime_s: float) -> bytes:
    """The CDR bytes of a scene's ``MarkerArray`` (what the simulator node publishes)."""
    return serialize(marker_array(scene_markers(scene, lifetime_s), stamp_ns))


def write_scene(bag: BagWriter, stamp_s: float, scene: BeamScene, lifetime_s: float) -> None:
    """Writes a scene's markers on ``/beam_markers``, stamped and logged at ``stamp_s``."""
    write_scene_ns(bag, convert.seconds_to_ns(stamp_s), scene, lifetime_s)


def write_scene_ns(
    bag: BagWriter,
    stamp_ns: int,
    scene: BeamScene,
    lifetime_s: float,
    log_time_ns: int | None = None,
) -> None:
    """Writes a scene's markers stamped ``stamp_ns`` exactly, logged at ``log_time_ns``.

    For markers drawn from a message of the bag (a tracked frame): its integer stamp and log
    time, so the markers sort with it. A stamp passed through float seconds comes back up to
    a few hundred ns off at today's epoch, which put markers out of log-time order.

    Args:
        bag: An open writer.
        stamp_ns: Header stamp, ns.
        scene: What to draw.
        lifetime_s: Marker lifetime, s.
        log_time_ns: Log time, ns (the stamp when ``None``).
    """
    log_time = stamp_ns if log_time_ns is None else log_time_ns
    markers = marker_array(scene_markers(scene, lifetime_s), stamp_ns)
    bag.write_message(MARKERS_TOPIC, markers, log_time)


def marker_specs(message: Any) -> list[MarkerSpec]:
    """The markers of a ``MarkerArray`` message (rosbags), for drawing them without ROS.

    Raises:
        ValueError: A marker type or action this package does not draw.
    """
    specs = []
    for m in message.markers:
        p, q, s, c = m.pose.position, m.pose.orientation, m.scale, m.color
        specs.append(
            MarkerSpec(
                namespace=m.ns,
                marker_id=int(m.id),
                shape=Shape(int(m.type)),
                action=Action(int(m.action)),
                position=(p.x, p.y, p.z),
                orientation=(q.x, q.y, q.z, q.w),
                scale=(s.x, s.y, s.z),
                color=(c.r, c.g, c.b, c.a),
                points=np.array([(v.x, v.y, v.z) for v in m.points]).reshape(-1, 3),
                lifetime_s=m.lifetime.sec + m.lifetime.nanosec / convert.NS_PER_S,
            )
        )
    return specs


def read_marker_arrays(bag: str | Path) -> Iterator[tuple[float, list[MarkerSpec]]]:
    """Yields ``(header stamp s, markers)`` of every ``/beam_markers`` message of a bag.

    Raises:
        BagError: The bag cannot be read or has no ``/beam_markers``.
    """
    reader = BagReader(bag)
    for _, message in reader.messages(MARKERS_TOPIC, MARKER_ARRAY_TYPE):
        stamp = message.markers[0].header.stamp if message.markers else None
        t = convert.ns_to_seconds(convert.time_ns(stamp)) if stamp is not None else 0.0
        yield t, marker_specs(message)
