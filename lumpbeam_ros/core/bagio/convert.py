"""Conversions between ROS messages (rosbags classes) and numbers / numpy arrays.

Conventions (doc/interfaces.md): poses are in frame ``beam_base`` (x toward the tip, z up);
the tip's pitch is its rotation about +y, positive when the tip bends down, so a pitch
``theta`` is the quaternion ``(w, x, y, z) = (cos theta/2, 0, sin theta/2, 0)``. Header stamps
are the time the measurement describes. Times are integer nanoseconds in messages and float
seconds in arrays.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from lumpbeam_ros.base.errors import BagError
from lumpbeam_ros.base.interface import (
    CAMERA_FRAME,
    CAMERA_INFO_TYPE,
    CLOCK_TYPE,
    COMPRESSED_IMAGE_TYPE,
    DIAGNOSTIC_ARRAY,
    FLOAT64,
    IMAGE_TYPE,
    IMU_TYPE,
    JOINT_STATE_TYPE,
    POINT_STAMPED,
    POSE_STAMPED,
)
from lumpbeam_ros.core.bagio.typestore import message_class

NS_PER_S = 1_000_000_000

#: Channels per pixel and sample type of the image encodings the project reads and writes
#: (names of ROS's ``sensor_msgs/image_encodings``); a Bayer mosaic is one raw channel.
IMAGE_ENCODINGS: dict[str, tuple[int, type[np.generic]]] = {
    'mono8': (1, np.uint8),
    'bgr8': (3, np.uint8),
    'rgb8': (3, np.uint8),
    'mono16': (1, np.uint16),
    'bayer_rggb8': (1, np.uint8),
    'bayer_bggr8': (1, np.uint8),
    'bayer_gbrg8': (1, np.uint8),
    'bayer_grbg8': (1, np.uint8),
}


def seconds_to_ns(seconds: float) -> int:
    """Converts seconds to integer nanoseconds, rounding to the nearest.

    Raises:
        BagError: Not finite, or negative (ROS times are unsigned).
    """
    if not math.isfinite(seconds) or seconds < 0.0:
        raise BagError(f'time must be a finite number >= 0 s, got {seconds!r}')
    return round(seconds * NS_PER_S)


def ns_to_seconds(ns: int) -> float:
    """Converts integer nanoseconds to float seconds."""
    return ns / NS_PER_S


def time_msg(ns: int) -> Any:
    """Builds a ``builtin_interfaces/msg/Time`` from nanoseconds."""
    sec, nanosec = divmod(int(ns), NS_PER_S)
    return message_class('builtin_interfaces/msg/Time')(sec=sec, nanosec=nanosec)


def time_ns(stamp: Any) -> int:
    """Returns the nanoseconds of a ``builtin_interfaces/msg/Time``."""
    return int(stamp.sec) * NS_PER_S + int(stamp.nanosec)


def header(ns: int, frame_id: str) -> Any:
    """Builds a ``std_msgs/msg/Header``."""
    return message_class('std_msgs/msg/Header')(stamp=time_msg(ns), frame_id=frame_id)


def pitch_to_quaternion(pitch: float) -> tuple[float, float, float, float]:
    """Returns the quaternion ``(x, y, z, w)`` of a rotation by ``pitch`` about +y."""
    half = 0.5 * pitch
    return 0.0, math.sin(half), 0.0, math.cos(half)


def quaternion_to_pitch(x: float, y: float, z: float, w: float) -> float:
    """Returns the pitch of an orientation: the slope of its rotated x axis.

    The rotated x axis is ``d = R e_x``; the pitch is ``atan2(-d_z, d_x)``, so a pure rotation
    about +y gives back its angle and small roll or yaw leave it unchanged to first order.
    The quaternion need not be normalized; a zero or non-finite one gives NaN.
    """
    return float(quaternions_to_pitch(np.array([[x, y, z, w]], dtype=float))[0])


def quaternions_to_pitch(xyzw: np.ndarray) -> np.ndarray:
    """:func:`quaternion_to_pitch` for an array of quaternions, shape (n, 4).

    A zero or non-finite quaternion gives a NaN pitch: the sample is then dropped and counted
    like one with a NaN position (:func:`~lumpbeam_ros.core.ident.samples.clean_window`).
    """
    x, y, z, w = xyzw.T
    with np.errstate(invalid='ignore', over='ignore'):
        norm2 = x * x + y * y + z * z + w * w
        bad = ~np.isfinite(norm2) | (norm2 == 0.0)
        s = 2.0 / np.where(bad, 1.0, norm2)
        d_x = 1.0 - s * (y * y + z * z)
        d_z = s * (x * z - w * y)
        return np.where(bad, np.nan, np.arctan2(-d_z, d_x))


def pose_stamped(ns: int, x: float, z: float, pitch: float, frame_id: str) -> Any:
    """Builds a ``geometry_msgs/msg/PoseStamped`` of a planar tip pose (y = 0)."""
    qx, qy, qz, qw = pitch_to_quaternion(pitch)
    point = message_class('geometry_msgs/msg/Point')(x=float(x), y=0.0, z=float(z))
    orientation = message_class('geometry_msgs/msg/Quaternion')(x=qx, y=qy, z=qz, w=qw)
    pose = message_class('geometry_msgs/msg/Pose')(position=point, orientation=orientation)
    return message_class(POSE_STAMPED)(header=header(ns, frame_id), pose=pose)


def pose_stamped_6dof(
    ns: int,
    position: tuple[float, float, float],
    quaternion: tuple[float, float, float, float],
    frame_id: str,
) -> Any:
    """Builds a ``geometry_msgs/msg/PoseStamped`` of a full pose.

    Args:
        ns: Stamp, ns.
        position: ``(x, y, z)``, m.
        quaternion: ``(x, y, z, w)``.
        frame_id: The header's frame.
    """
    point = message_class('geometry_msgs/msg/Point')(*(float(v) for v in position))
    qx, qy, qz, qw = (float(v) for v in quaternion)
    orientation = message_class('geometry_msgs/msg/Quaternion')(x=qx, y=qy, z=qz, w=qw)
    pose = message_class('geometry_msgs/msg/Pose')(position=point, orientation=orientation)
    return message_class(POSE_STAMPED)(header=header(ns, frame_id), pose=pose)


def pose_values(msg: Any) -> tuple[int, float, float, float, str]:
    """Returns ``(stamp_ns, x, z, pitch, frame_id)`` of a ``PoseStamped``."""
    p = msg.pose.position
    q = msg.pose.orientation
    pitch = quaternion_to_pitch(q.x, q.y, q.z, q.w)
    return time_ns(msg.header.stamp), float(p.x), float(p.z), pitch, msg.header.frame_id


def imu_acceleration(ns: int, acceleration: tuple[float, float, float], frame_id: str) -> Any:
    """Builds a ``sensor_msgs/msg/Imu`` that carries only a linear acceleration.

    The orientation and the angular velocity are marked unknown (element 0 of their
    covariance -1, as the message's definition asks); the acceleration's covariance is all
    zeros, "unknown" too.

    Args:
        ns: Stamp, ns.
        acceleration: ``(x, y, z)``, m/s^2, in ``frame_id``.
        frame_id: The sensor's frame.
    """
    vector = message_class('geometry_msgs/msg/Vector3')
    unknown = np.zeros(9)
    unknown[0] = -1.0
    return message_class(IMU_TYPE)(
        header=header(ns, frame_id),
        orientation=message_class('geometry_msgs/msg/Quaternion')(x=0.0, y=0.0, z=0.0, w=1.0),
        orientation_covariance=unknown,
        angular_velocity=vector(x=0.0, y=0.0, z=0.0),
        angular_velocity_covariance=unknown.copy(),
        linear_acceleration=vector(*(float(v) for v in acceleration)),
        linear_acceleration_covariance=np.zeros(9),
    )


def imu_acceleration_values(msg: Any) -> tuple[int, float, float, float, str]:
    """Returns ``(stamp_ns, ax, ay, az, frame_id)`` of a ``sensor_msgs/msg/Imu``."""
    a = msg.linear_acceleration
    return time_ns(msg.header.stamp), float(a.x), float(a.y), float(a.z), msg.header.frame_id


def float64(value: float) -> Any:
    """Builds a ``std_msgs/msg/Float64``."""
    return message_class(FLOAT64)(data=float(value))


def joint_state(ns: int, names: Iterable[str], positions: np.ndarray) -> Any:
    """Builds a ``sensor_msgs/msg/JointState`` of joint angles (rad), without rates or efforts.

    Args:
        ns: Stamp, ns.
        names: One name per joint (``joint_1`` ...).
        positions: The angles, rad.
    """
    return message_class(JOINT_STATE_TYPE)(
        header=header(ns, ''),
        name=list(names),
        position=np.asarray(positions, dtype=np.float64),
        velocity=np.zeros(0),
        effort=np.zeros(0),
    )


def joint_state_values(msg: Any) -> tuple[int, list[str], np.ndarray]:
    """Returns ``(stamp_ns, names, positions)`` of a ``JointState``."""
    return time_ns(msg.header.stamp), list(msg.name), np.asarray(msg.position, dtype=float)


def point_stamped(ns: int, x: float, y: float, z: float, frame_id: str) -> Any:
    """Builds a ``geometry_msgs/msg/PointStamped``."""
    point = message_class('geometry_msgs/msg/Point')(x=float(x), y=float(y), z=float(z))
    return message_class(POINT_STAMPED)(header=header(ns, frame_id), point=point)


def point_values(msg: Any) -> tuple[int, float, float, float, str]:
    """Returns ``(stamp_ns, x, y, z, frame_id)`` of a ``PointStamped``."""
    p = msg.point
    return time_ns(msg.header.stamp), float(p.x), float(p.y), float(p.z), msg.header.frame_id


def clock(ns: int) -> Any:
    """Builds a ``rosgraph_msgs/msg/Clock``."""
    return message_class(CLOCK_TYPE)(clock=time_msg(ns))


def image(ns: int, pixels: np.ndarray, frame_id: str, encoding: str | None = None) -> Any:
    """Builds a ``sensor_msgs/msg/Image`` from an array.

    Args:
        ns: Exposure time, ns.
        pixels: ``(height, width)`` for mono8, mono16 and the Bayer mosaics,
            ``(height, width, 3)`` for bgr8/rgb8; uint16 for mono16, uint8 otherwise.
        frame_id: The camera's optical frame.
        encoding: One of :data:`IMAGE_ENCODINGS`; ``None`` means mono8 for a 2-D array and
            bgr8 (OpenCV's order) for a 3-channel one.

    Returns:
        The message, rows packed (``step = width * channels * bytes per sample``), little
        endian.

    Raises:
        BagError: A sample type or shape that does not fit the encoding, or an unknown
            encoding.
    """
    pixels = np.asarray(pixels)
    if encoding is None:
        encoding = 'mono8' if pixels.ndim == 2 else 'bgr8'
    if encoding not in IMAGE_ENCODINGS:
        raise BagError(f'unsupported image encoding {encoding!r} (use {sorted(IMAGE_ENCODINGS)})')
    channels, dtype = IMAGE_ENCODINGS[encoding]
    if pixels.dtype != dtype:
        raise BagError(f'{encoding} image must be {np.dtype(dtype)}, got {pixels.dtype}')
    expected_ndim = 2 if channels == 1 else 3
    if pixels.ndim != expected_ndim or (channels > 1 and pixels.shape[2] != channels):
        raise BagError(f'image of shape {pixels.shape} does not fit encoding {encoding}')
    height, width = pixels.shape[:2]
    data = np.ascontiguousarray(pixels, dtype=np.dtype(dtype).newbyteorder('<'))
    return message_class(IMAGE_TYPE)(
        header=header(ns, frame_id),
        height=height,
        width=width,
        encoding=encoding,
        is_bigendian=0,
        step=width * channels * data.itemsize,
        data=data.view(np.uint8).reshape(-1),
    )


def image_array(msg: Any) -> np.ndarray:
    """Returns the pixels of a ``sensor_msgs/msg/Image`` as an array (a view when possible).

    Args:
        msg: The image message.

    Returns:
        ``(height, width)`` for mono8, mono16 and the Bayer mosaics, ``(height, width, 3)``
        for bgr8/rgb8 (channel order as the encoding says); uint16 (native byte order) for
        mono16, uint8 otherwise.

    Raises:
        BagError: Unsupported encoding, a step shorter than a row, or a data size that does not
            match ``step * height``.
    """
    encoding = msg.encoding
    if encoding not in IMAGE_ENCODINGS:
        raise BagError(f'unsupported image encoding {encoding!r} (use {sorted(IMAGE_ENCODINGS)})')
    channels, dtype = IMAGE_ENCODINGS[encoding]
    itemsize = np.dtype(dtype).itemsize
    height, width, step = int(msg.height), int(msg.width), int(msg.step)
    row = width * channels * itemsize
    if step < row:
        raise BagError(f'image step {step} is shorter than a {encoding} row of {row} bytes')
    data = np.frombuffer(msg.data, dtype=np.uint8)
    if data.size != step * height:
        raise BagError(
            f'image data has {data.size} bytes, expected step*height = {step}*{height} = '
            f'{step * height}'
        )
    rows = data.reshape(height, step)[:, :row]
    if itemsize > 1:
        order: Literal['>', '<'] = '>' if msg.is_bigendian else '<'
        samples = np.ascontiguousarray(rows).view(np.dtype(dtype).newbyteorder(order))
        rows = samples.astype(dtype, copy=False)
    return rows.reshape(height, width) if channels == 1 else rows.reshape(height, width, channels)


def compressed_image(ns: int, data: bytes, image_format: str, frame_id: str) -> Any:
    """Builds a ``sensor_msgs/msg/CompressedImage``.

    Args:
        ns: Exposure time, ns.
        data: The encoded image (the bytes of a JPEG or PNG file).
        image_format: ``format`` as image_transport writes it, e.g. ``'jpeg'``, ``'png'`` or
            ``'mono8; jpeg compressed mono8'``.
        frame_id: The camera's optical frame.

    Returns:
        The message.
    """
    return message_class(COMPRESSED_IMAGE_TYPE)(
        header=header(ns, frame_id),
        format=image_format,
        data=np.frombuffer(bytes(data), dtype=np.uint8),
    )


@dataclass(frozen=True)
class CameraInfoData:
    """The calibration a ``sensor_msgs/msg/CameraInfo`` carries.

    Attributes:
        width: Image width, px.
        height: Image height, px.
        k: 3x3 intrinsic matrix.
        d: Distortion coefficients.
        distortion_model: E.g. ``'plumb_bob'``.
        frame_id: The camera's optical frame.
        r: 3x3 rectification matrix (identity for a monocular camera).
        p: 3x4 projection matrix; ``[K | 0]`` when not given.
    """

    width: int
    height: int
    k: np.ndarray
    d: np.ndarray = field(default_factory=lambda: np.zeros(5))
    distortion_model: str = 'plumb_bob'
    frame_id: str = CAMERA_FRAME
    r: np.ndarray = field(default_factory=lambda: np.eye(3))
    p: np.ndarray | None = None


def camera_info(ns: int, info: CameraInfoData) -> Any:
    """Builds a ``sensor_msgs/msg/CameraInfo``.

    Raises:
        BagError: Matrices of the wrong shape or non-positive image size.
    """
    k = np.asarray(info.k, dtype=np.float64)
    r = np.asarray(info.r, dtype=np.float64)
    p = np.zeros((3, 4)) if info.p is None else np.asarray(info.p, np.float64)
    if k.shape != (3, 3) or r.shape != (3, 3) or p.shape != (3, 4):
        raise BagError(
            f'camera info needs K 3x3, R 3x3, P 3x4; got {k.shape}, {r.shape}, {p.shape}'
        )
    if info.width <= 0 or info.height <= 0:
        raise BagError(f'camera info image size must be positive, got {info.width}x{info.height}')
    if info.p is None:
        p = np.hstack([k, np.zeros((3, 1))])  # a monocular camera's P is [K | 0]
    roi = message_class('sensor_msgs/msg/RegionOfInterest')(
        x_offset=0, y_offset=0, height=0, width=0, do_rectify=False
    )
    return message_class(CAMERA_INFO_TYPE)(
        header=header(ns, info.frame_id),
        height=int(info.height),
        width=int(info.width),
        distortion_model=info.distortion_model,
        d=np.asarray(info.d, dtype=np.float64).reshape(-1),
        k=k.reshape(-1),
        r=r.reshape(-1),
        p=p.reshape(-1),
        binning_x=0,
        binning_y=0,
        roi=roi,
    )


def camera_info_data(msg: Any) -> CameraInfoData:
    """Returns the calibration of a ``sensor_msgs/msg/CameraInfo``."""
    return CameraInfoData(
        width=int(msg.width),
        height=int(msg.height),
        k=np.asarray(msg.k, dtype=np.float64).reshape(3, 3),
        d=np.asarray(msg.d, dtype=np.float64).copy(),
        distortion_model=msg.distortion_model,
        frame_id=msg.header.frame_id,
        r=np.asarray(msg.r, dtype=np.float64).reshape(3, 3),
        p=np.asarray(msg.p, dtype=np.float64).reshape(3, 4),
    )


@dataclass(frozen=True)
class Status:
    """One ``diagnostic_msgs/msg/DiagnosticStatus``.

    Attributes:
        name: E.g. ``'lumpbeam/identifier'``.
        level: 0 OK, 1 WARN, 2 ERROR, 3 STALE.
        message: Human-readable summary.
        values: Key-value pairs (values as strings; doc/interfaces.md uses ``repr`` of floats).
        hardware_id: Optional hardware identifier.
    """

    name: str
    level: int
    message: str
    values: Mapping[str, str] = field(default_factory=dict)
    hardware_id: str = ''


def diagnostic_array(ns: int, statuses: Iterable[Status], frame_id: str = '') -> Any:
    """Builds a ``diagnostic_msgs/msg/DiagnosticArray``.

    Raises:
        BagError: A level outside 0..3.
    """
    status_cls = message_class('diagnostic_msgs/msg/DiagnosticStatus')
    key_value = message_class('diagnostic_msgs/msg/KeyValue')
    built = []
    for s in statuses:
        if s.level not in (0, 1, 2, 3):
            raise BagError(f'diagnostic level must be 0..3, got {s.level!r} for {s.name!r}')
        values = [key_value(key=str(k), value=str(v)) for k, v in s.values.items()]
        built.append(
            status_cls(
                level=s.level,
                name=s.name,
                message=s.message,
                hardware_id=s.hardware_id,
                values=values,
            )
        )
    return message_class(DIAGNOSTIC_ARRAY)(header=header(ns, frame_id), status=built)


def diagnostic_statuses(msg: Any) -> list[Status]:
    """Returns the statuses of a ``diagnostic_msgs/msg/DiagnosticArray``."""
    return [
        Status(
            name=s.name,
            level=int(s.level),
            message=s.message,
            values={kv.key: kv.value for kv in s.values},
            hardware_id=s.hardware_id,
        )
        for s in msg.status
    ]
