"""Camera messages serialized by rclpy (not by the package), and images encoded by Pillow."""

from __future__ import annotations

import io

import numpy as np
import pytest
from PIL import Image

serialization = pytest.importorskip('rclpy.serialization')
sensor_msgs = pytest.importorskip('sensor_msgs.msg')

#: An epoch stamp, ns, as a camera driver's header carries.
STAMP_NS = 1_700_000_000_123_456_789

#: Bytes per sample and channels of the encodings built here.
LAYOUT = {
    'mono8': (1, 1),
    'mono16': (2, 1),
    'bgr8': (1, 3),
    'rgb8': (1, 3),
    'bayer_rggb8': (1, 1),
    'bayer_bggr8': (1, 1),
    'bayer_gbrg8': (1, 1),
    'bayer_grbg8': (1, 1),
}


def _header(message, stamp_ns: int, frame_id: str):
    message.header.stamp.sec, message.header.stamp.nanosec = divmod(stamp_ns, 10**9)
    message.header.frame_id = frame_id
    return message


def image_cdr(
    pixels: np.ndarray,
    encoding: str,
    stamp_ns: int = STAMP_NS,
    frame_id: str = 'camera_optical',
    padding: int = 0,
) -> bytes:
    """A ``sensor_msgs/msg/Image`` serialized by rclpy.

    Args:
        pixels: ``(h, w)`` or ``(h, w, 3)`` samples.
        encoding: The message's encoding (any string; the layout of :data:`LAYOUT` if known).
        stamp_ns: Header stamp.
        frame_id: Header frame.
        padding: Bytes added after each row (``step`` beyond the row's length).
    """
    message = _header(sensor_msgs.Image(), stamp_ns, frame_id)
    height, width = pixels.shape[:2]
    rows = np.ascontiguousarray(pixels).view(np.uint8).reshape(height, -1)
    rows = np.hstack([rows, np.full((height, padding), 0xEE, np.uint8)])
    message.height, message.width, message.encoding = height, width, encoding
    message.is_bigendian = 0
    message.step = rows.shape[1]
    message.data = rows.tobytes()
    return serialization.serialize_message(message)


def compressed_cdr(data: bytes, image_format: str, stamp_ns: int = STAMP_NS) -> bytes:
    """A ``sensor_msgs/msg/CompressedImage`` serialized by rclpy."""
    message = _header(sensor_msgs.CompressedImage(), stamp_ns, 'camera_optical')
    message.format = image_format
    message.data = data
    return serialization.serialize_message(message)


def camera_info_cdr(
    width: int, height: int, k: np.ndarray, d: np.ndarray, model: str = 'plumb_bob'
) -> bytes:
    """A ``sensor_msgs/msg/CameraInfo`` serialized by rclpy."""
    message = _header(sensor_msgs.CameraInfo(), STAMP_NS, 'camera_optical')
    message.width, message.height = width, height
    message.k = [float(v) for v in np.ravel(k)]
    message.d = [float(v) for v in d]
    message.distortion_model = model
    return serialization.serialize_message(message)


def encoded(pixels: np.ndarray, image_format: str, mode: str | None = None) -> bytes:
    """Pixels as a PNG or JPEG file written by Pillow (RGB order for colour)."""
    buffer = io.BytesIO()
    Image.fromarray(pixels, mode).save(buffer, format=image_format, quality=95)
    return buffer.getvalue()
