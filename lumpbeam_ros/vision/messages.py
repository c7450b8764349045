"""Camera messages to tracker inputs: the one place where bagio's types meet the vision core.

Images and camera infos arrive as CDR bytes, from a live topic (a raw subscription) or from
a bag; both are decoded here with bagio's typestore and converters, so the node, ``lumpbeam
track`` and the synthetic bags agree on every field. Decoding failures are
:class:`~lumpbeam_ros.errors.BagError` / :class:`~lumpbeam_ros.errors.LumpbeamError`, one
line each, for the caller to turn into a warning.
"""

from __future__ import annotations

import numpy as np

from lumpbeam_ros.bagio import CameraInfoData, ImageFrame, convert
from lumpbeam_ros.bagio.typestore import deserialize
from lumpbeam_ros.vision.camera_model import CameraInfo

IMAGE_TYPE = 'sensor_msgs/msg/Image'
CAMERA_INFO_TYPE = 'sensor_msgs/msg/CameraInfo'


def camera_info_from_data(data: CameraInfoData) -> CameraInfo:
    """Converts bagio's calibration record into the tracker's camera model.

    Args:
        data: From :func:`~lumpbeam_ros.bagio.read_camera_info` or :func:`decode_camera_info`.

    Returns:
        The camera model.

    Raises:
        LumpbeamError: An unusable calibration: zero focal length (an uncalibrated camera
            publishes K = 0), a distortion model other than plumb_bob, a bad size.
    """
    return CameraInfo(
        int(data.width),
        int(data.height),
        np.asarray(data.k, dtype=float),
        np.asarray(data.d, dtype=float),
        data.distortion_model,
    )


def camera_info_to_data(info: CameraInfo, frame_id: str = 'camera') -> CameraInfoData:
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


def decode_image(data: bytes | memoryview) -> ImageFrame:
    """Decodes a serialized ``sensor_msgs/msg/Image``; the pixels are a view of ``data``.

    Args:
        data: CDR bytes (a raw subscription's message, or a bag record).

    Returns:
        The frame: stamp (s), pixels ``(h, w)`` or ``(h, w, 3)``, encoding, frame id.

    Raises:
        BagError: Corrupt bytes, an unsupported encoding, or a data size that does not
            match ``step * height``.
    """
    msg = deserialize(data, IMAGE_TYPE)
    pixels = convert.image_array(msg)
    stamp = convert.ns_to_seconds(convert.time_ns(msg.header.stamp))
    return ImageFrame(stamp, pixels, msg.encoding, msg.header.frame_id)


def decode_camera_info(data: bytes | memoryview) -> CameraInfo:
    """Decodes a serialized ``sensor_msgs/msg/CameraInfo`` into the camera model.

    Raises:
        BagError: Corrupt bytes.
        LumpbeamError: An unusable calibration (see :func:`camera_info_from_data`).
    """
    return camera_info_from_data(convert.camera_info_data(deserialize(data, CAMERA_INFO_TYPE)))
