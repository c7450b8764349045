"""Camera messages to tracker inputs: the one place where bagio's types meet the vision core.

Images and camera infos arrive as CDR bytes, from a live topic (a raw subscription) or from
a bag; both are decoded here with bagio's typestore and converters, so the node, ``lumpbeam
track`` and the synthetic bags agree on every field. Decoding failures are
:class:`~lumpbeam_ros.base.errors.BagError` / :class:`~lumpbeam_ros.base.errors.LumpbeamError`, one
line each, for the caller to turn into a warning.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from lumpbeam_ros.base.errors import BagError, LumpbeamError
from lumpbeam_ros.base.interface import (
    CAMERA_FRAME,
    CAMERA_INFO_TYPE,
    COMPRESSED_IMAGE_TYPE,
    IMAGE_TYPE,
)
from lumpbeam_ros.core.bagio import CameraInfoData, convert
from lumpbeam_ros.core.bagio.typestore import deserialize, prepare
from lumpbeam_ros.core.vision.camera_model import CameraInfo, check_image_side
from lumpbeam_ros.core.vision.sources.pixels import decode_compressed, tracker_pixels

#: The image message types the tracker reads.
IMAGE_TYPES = (IMAGE_TYPE, COMPRESSED_IMAGE_TYPE)
#: Where the stamp ends in the CDR bytes of a message that starts with a ``std_msgs/Header``:
#: after the 4-byte encapsulation header, ``sec`` (int32) and ``nanosec`` (uint32).
HEADER_STAMP_END = 12


class CameraFrame(NamedTuple):
    """One decoded image.

    Attributes:
        stamp_ns: Header stamp, ns (exact: a pose carries it unchanged).
        pixels: ``(h, w)`` for mono8, ``(h, w, 3)`` for bgr8/rgb8, uint8 (other encodings
            are converted on decoding, see :mod:`lumpbeam_ros.core.vision.sources.pixels`).
        encoding: ``'mono8'``, ``'bgr8'`` or ``'rgb8'``.
        frame_id: The camera's optical frame.
    """

    stamp_ns: int
    pixels: np.ndarray
    encoding: str
    frame_id: str

    @property
    def stamp(self) -> float:
        """The stamp in seconds (what the tracker works with)."""
        return convert.ns_to_seconds(self.stamp_ns)


def camera_info_from_data(data: CameraInfoData) -> CameraInfo:
    """Converts bagio's calibration record into the tracker's camera model.

    Args:
        data: From :func:`~lumpbeam_ros.core.bagio.read_camera_info` or :func:`decode_camera_info`.

    Returns:
        The camera model.

    Raises:
        LumpbeamError: An unusable calibration: zero focal length (an uncalibrated camera
            publishes K = 0), a distortion model other than plumb_bob,
            rational_polynomial and equidistant, a bad size.
    """
    return CameraInfo(
        int(data.width),
        int(data.height),
        np.asarray(data.k, dtype=float),
        np.asarray(data.d, dtype=float),
        data.distortion_model,
    )


def camera_info_to_data(info: CameraInfo, frame_id: str = CAMERA_FRAME) -> CameraInfoData:
    """Converts the camera model into bagio's record (for writing ``/camera/camera_info``).

    Args:
        info: The camera model.
        frame_id: The camera's optical frame.

    Returns:
        The record (R identity, P = [K | 0]: a monocular camera).
    """
    return CameraInfoData(
        width=info.width,
        height=info.height,
        k=info.k.copy(),
        d=info.d.copy(),
        distortion_model=info.distortion_model,
        frame_id=frame_id,
    )


def decode_image(data: bytes | memoryview) -> CameraFrame:
    """Decodes a serialized ``sensor_msgs/msg/Image`` into tracker-ready pixels.

    Args:
        data: CDR bytes (a raw subscription's message, or a bag record).

    Returns:
        The frame; mono16 and Bayer images come out as mono8.

    Raises:
        BagError: Corrupt bytes, an unsupported encoding, a data size that does not
            match ``step * height``, or a side past
            :data:`~lumpbeam_ros.core.vision.camera_model.MAX_IMAGE_SIDE_PX`.
    """
    msg = deserialize(data, IMAGE_TYPE)
    try:
        check_image_side(int(msg.width), int(msg.height), 'image')
    except LumpbeamError as exc:
        raise BagError(str(exc)) from None
    pixels, encoding = tracker_pixels(convert.image_array(msg), msg.encoding)
    return CameraFrame(convert.time_ns(msg.header.stamp), pixels, encoding, msg.header.frame_id)


def decode_compressed_image(data: bytes | memoryview) -> CameraFrame:
    """Decodes a serialized ``sensor_msgs/msg/CompressedImage`` (JPEG or PNG).

    Args:
        data: CDR bytes.

    Returns:
        The frame (mono8 for a grey image, bgr8 for a colour one).

    Raises:
        BagError: Corrupt bytes, a corrupt or truncated JPEG or PNG, or a depth image.
    """
    msg = deserialize(data, COMPRESSED_IMAGE_TYPE)
    pixels, encoding = decode_compressed(msg.data, msg.format)
    return CameraFrame(convert.time_ns(msg.header.stamp), pixels, encoding, msg.header.frame_id)


def decode_frame(data: bytes | memoryview, msgtype: str = IMAGE_TYPE) -> CameraFrame:
    """Decodes an image message of either type in :data:`IMAGE_TYPES`.

    Raises:
        BagError: As :func:`decode_image` or :func:`decode_compressed_image`, or another type.
    """
    if msgtype == COMPRESSED_IMAGE_TYPE:
        return decode_compressed_image(data)
    if msgtype == IMAGE_TYPE:
        return decode_image(data)
    raise BagError(f'{msgtype} is not an image type ({", ".join(IMAGE_TYPES)})')


def prepare_decoders() -> None:
    """Readies the decoders of images and camera infos before the first frame comes.

    See :func:`~lumpbeam_ros.core.bagio.typestore.prepare`: a live node calls this before it
    subscribes, so its first frame costs what the others do.
    """
    prepare((*IMAGE_TYPES, CAMERA_INFO_TYPE))


def decode_camera_info(data: bytes | memoryview) -> CameraInfo:
    """Decodes a serialized ``sensor_msgs/msg/CameraInfo`` into the camera model.

    Raises:
        BagError: Corrupt bytes.
        LumpbeamError: An unusable calibration (see :func:`camera_info_from_data`).
    """
    return camera_info_from_data(convert.camera_info_data(deserialize(data, CAMERA_INFO_TYPE)))
