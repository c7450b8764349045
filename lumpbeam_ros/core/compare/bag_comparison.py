"""Reading the comparison's input from a bag: camera poses, reference points, loads."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lumpbeam_ros.base.errors import BagError, LumpbeamError
from lumpbeam_ros.base.interface import BASE_FRAME, TIP_LOAD, TIP_POSE, TRACKER_POINT
from lumpbeam_ros.core.bagio import (
    BagReader,
    open_bag,
    read_load_events,
    read_points,
    read_tip_poses,
)
from lumpbeam_ros.core.bagio.tipseries import LoadSeries
from lumpbeam_ros.core.compare.streams import Track, clean_track
from lumpbeam_ros.core.ident.samples import clean_loads

CAMERA_TOPIC = TIP_POSE
REFERENCE_TOPIC = TRACKER_POINT
LOAD_TOPIC = TIP_LOAD


@dataclass(frozen=True)
class ComparisonInput:
    """What :func:`~.comparison.compare_sensors` takes, read from one bag.

    Attributes:
        camera: Camera tip positions in ``beam_base`` (``y = 0``), with pitch.
        reference: Reference positions in the reference's frame and clock.
        loads: ``/tip_load`` readings, or ``None`` when the bag has none.
    """

    camera: Track
    reference: Track
    loads: LoadSeries | None


def read_comparison_input(
    bag: str | Path | BagReader,
    camera_topic: str = CAMERA_TOPIC,
    reference_topic: str = REFERENCE_TOPIC,
    load_topic: str = LOAD_TOPIC,
) -> ComparisonInput:
    """Reads both sensors (and the loads, if recorded) from a bag.

    Args:
        bag: Bag folder or open reader.
        camera_topic: ``geometry_msgs/msg/PoseStamped`` in ``beam_base``.
        reference_topic: ``geometry_msgs/msg/PointStamped`` in the reference frame.
        load_topic: ``std_msgs/msg/Float64``, optional.

    Returns:
        The cleaned streams.

    Raises:
        BagError: The bag is unreadable, a sensor is missing, empty or of another type, or
            the camera poses are not in ``beam_base``.
    """
    reader = open_bag(bag)
    missing = [
        f'{role} ({topic})'
        for role, topic in (('camera poses', camera_topic), ('reference sensor', reference_topic))
        if topic not in reader.topics
    ]
    if missing:
        raise BagError(
            f'{reader.path}: no {" and no ".join(missing)}; compare needs {camera_topic} and '
            f'{reference_topic} recorded together'
        )
    poses = read_tip_poses(reader, camera_topic)
    # The camera's tip poses are in the beam's base frame (not interface.CAMERA_FRAME, the
    # frame of its images): the tracker has already placed them on the beam.
    if poses.t.size and poses.frame_id != BASE_FRAME:
        raise BagError(
            f'{reader.path}: {camera_topic} is in frame {poses.frame_id!r}, not {BASE_FRAME!r}'
        )
    camera_points = np.column_stack([poses.x, np.zeros_like(poses.x), poses.z])
    camera = _track(reader, poses.t, camera_points, BASE_FRAME, camera_topic, pitch=poses.pitch)
    points = read_points(reader, reference_topic)
    reference = _track(
        reader,
        points.t,
        np.column_stack([points.x, points.y, points.z]),
        points.frame_id,
        reference_topic,
    )
    loads = None
    if load_topic in reader.topics:
        events = read_load_events(reader, load_topic)
        loads = clean_loads(events.t, events.kg) if events.t.size else None
    return ComparisonInput(camera, reference, loads)


def _track(
    reader: BagReader,
    t: np.ndarray,
    points: np.ndarray,
    frame_id: str,
    topic: str,
    pitch: np.ndarray | None = None,
) -> Track:
    if t.size == 0:
        raise BagError(f'{reader.path}: topic {topic} has no message')
    try:
        return clean_track(t, points, frame_id, topic, pitch)
    except LumpbeamError as exc:  # say which bag
        raise BagError(f'{reader.path}: {exc}') from None
