"""The one loop over a bag's camera frames, for the camera node and ``lumpbeam track``.

:func:`bag_frames` walks a bag's messages in recording order: a camera info of the
calibration topic goes to the :class:`~lumpbeam_ros.core.vision.session.TrackingSession` (a
change rebuilds its tracker), an image of the image topic is decoded (``Image`` or
``CompressedImage``), and each message comes out as a :class:`BagItem` saying which it was
and what became of it. The caller tracks the frames and does with the poses what it is for:
the camera node publishes them (:meth:`~lumpbeam_ros.nodes.camera_node.CameraNode.run_bag`),
``lumpbeam track`` writes them beside a copy of the bag
(:func:`~lumpbeam_ros.core.vision.offline.track_bag`). A message that does not decode is an item
with its ``problem``, never the end of the bag.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import Literal

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.bagio.reader import BagReader, RawMessage
from lumpbeam_ros.core.vision.messages import CameraFrame, decode_frame
from lumpbeam_ros.core.vision.session import TrackingSession

ItemKind = Literal['image', 'camera_info', 'other']


@dataclass(frozen=True)
class BagItem:
    """One message of the bag, as the tracking loop saw it.

    Attributes:
        raw: The message as stored.
        kind: ``'image'`` (of the image topic), ``'camera_info'`` (of the calibration topic,
            when it is followed) or ``'other'``.
        frame: The decoded image (``None`` when it did not decode, or not an image).
        problem: Why an image or a camera info was not used (``''``: it was).
        info_changed: Whether a camera info rebuilt the session's tracker.
        index: The image's place among the topic's images, from 0 (-1: not an image).
    """

    raw: RawMessage
    kind: ItemKind
    frame: CameraFrame | None = None
    problem: str = ''
    info_changed: bool = False
    index: int = -1


def bag_frames(
    reader: BagReader,
    session: TrackingSession,
    image_topic: str,
    image_type: str,
    camera_info_topic: str,
    *,
    follow_info: bool = True,
    topics: Iterable[str] | None = None,
    should_stop: Callable[[], bool] = lambda: False,
) -> Iterator[BagItem]:
    """The bag's messages in recording order, camera infos applied and images decoded.

    Args:
        reader: The open bag.
        session: Takes the camera infos (:meth:`TrackingSession.set_camera_info`).
        image_topic: The images to decode.
        image_type: Their type (``sensor_msgs/msg/Image`` or ``.../CompressedImage``).
        camera_info_topic: The calibration topic.
        follow_info: Apply the bag's camera infos (``False``: the session's intrinsics came
            from elsewhere and stay; the infos are ``'other'`` items).
        topics: The topics to read (``None``: all, e.g. to copy them).
        should_stop: Polled before each message; ``True`` ends the walk.

    Yields:
        One item per message.
    """
    index = 0
    for raw in reader.iter_raw(topics):
        if should_stop():
            return
        if raw.topic == camera_info_topic and follow_info:
            try:
                changed = session.set_camera_info_message(raw.data)
            except LumpbeamError as exc:
                yield BagItem(raw, 'camera_info', problem=str(exc))
            else:
                yield BagItem(raw, 'camera_info', info_changed=changed)
        elif raw.topic == image_topic:
            try:
                frame = decode_frame(raw.data, image_type)
            except LumpbeamError as exc:
                yield BagItem(raw, 'image', problem=str(exc), index=index)
            else:
                yield BagItem(raw, 'image', frame=frame, index=index)
            index += 1
        else:
            yield BagItem(raw, 'other')
