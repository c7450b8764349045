"""Whole topics as numpy arrays: what the offline commands (analyze, diagnose) read.

Times are header stamps (measurement time, doc/interfaces.md) in float seconds, sorted; a topic
without a header (``std_msgs/Float64``) uses the log time, which equals the stamp in
synthetic bags and is the receive time in recorded ones.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator, Sequence
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from lumpbeam_ros.base.errors import BagError
from lumpbeam_ros.base.interface import (
    BEAM_PARAMS,
    CAMERA_INFO,
    IMAGE,
    IMU_TYPE,
    JOINT_STATE_TYPE,
    JOINT_STATES,
    POINT_STAMPED,
    POSE_STAMPED,
    TIP_IMU,
    TIP_LOAD,
    TIP_POSE,
    TRACKER_POINT,
)
from lumpbeam_ros.core.bagio import convert, fastscan
from lumpbeam_ros.core.bagio.reader import BagReader, open_bag
from lumpbeam_ros.core.bagio.tipseries import LoadSeries, TipSeries

Bag = str | Path | BagReader


class PointSeries(NamedTuple):
    """Stamped 3-vectors and their frame: ``t, x, y, z`` arrays.

    Reference points (``/tracker/point``, m) or the tip's acceleration (``/tip_imu``, m/s^2).
    """

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    frame_id: str


class ImageFrame(NamedTuple):
    """One image: exposure time ``t`` (s), ``pixels`` (uint8), ``encoding``, ``frame_id``."""

    t: float
    pixels: np.ndarray
    encoding: str
    frame_id: str


def _stamp_s(msg: object) -> float:
    return convert.ns_to_seconds(convert.time_ns(msg.header.stamp))  # type: ignore[attr-defined]


def _stamped_columns(
    values: Iterable[tuple[int, float, float, float, str]], bag: BagReader, topic: str
) -> tuple[list[np.ndarray], str]:
    """The decoded messages of a stamped topic as columns, and the one frame they are in.

    Args:
        values: ``(stamp_ns, a, b, c, frame_id)`` per message, as :mod:`~.convert` decodes
            a pose or a point.
        bag: The bag they come from (for the error message).
        topic: Their topic.

    Returns:
        ``[t, a, b, c]`` sorted by stamp (t in s), and the frame (``''`` for no message).

    Raises:
        BagError: The messages are in more than one frame.
    """
    rows, frames = [], set()
    for ns, a, b, c, frame in values:
        rows.append((convert.ns_to_seconds(ns), a, b, c))
        frames.add(frame)
    if len(frames) > 1:
        raise BagError(f'{bag.path}: topic {topic} mixes frames {sorted(frames)}')
    return _sorted_columns(rows, 4), next(iter(frames), '')


def _sorted_columns(rows: Sequence[tuple[float, ...]], width: int) -> list[np.ndarray]:
    table = np.asarray(rows, dtype=np.float64).reshape(-1, width)
    table = table[np.argsort(table[:, 0], kind='stable')]
    return [table[:, i].copy() for i in range(width)]


def read_tip_poses(bag: Bag, topic: str = TIP_POSE, *, fast: bool = True) -> TipSeries:
    """Reads a ``geometry_msgs/PoseStamped`` topic as planar tip poses: the one reader of them.

    Args:
        bag: Bag folder or open reader.
        topic: E.g. ``'/tip_pose'``, ``'/tip_pose_truth'``, ``'/tip_pose_predicted'``.
        fast: Decode the topic in one vectorized pass (:mod:`~lumpbeam_ros.core.bagio.fastscan`)
            when its messages allow it; ``False`` always takes the general, per-message
            decoder. Both read the same verified messages.

    Returns:
        The poses sorted by stamp (empty arrays for an empty topic).

    Raises:
        BagError: Missing topic, another type or mixed frames (a message that does not
            decode is skipped and counted).
    """
    reader = open_bag(bag)
    reader.require(topic, 'geometry_msgs/msg/PoseStamped')
    if fast:
        poses = _fast_poses(reader, topic)
        if poses is not None:
            return poses
    decoded = (convert.pose_values(m) for _, m in reader.messages(topic, POSE_STAMPED))
    (t, x, z, pitch), frame = _stamped_columns(decoded, reader, topic)
    return TipSeries(t, x, z, pitch, frame_id=frame)


def _fast_scan(reader: BagReader, topic: str) -> tuple[list[int], list[bytes]]:
    """Log times and payloads of a topic across a bag's files, read past any damage.

    What damaged data lost is not reported yet: the caller reports it once it knows whether
    every payload decodes (:meth:`~.BagReader.report_loss`).
    """
    log_times: list[int] = []
    payloads: list[bytes] = []
    for raw in reader.iter_raw([topic], report=False):
        log_times.append(raw.log_time_ns)
        payloads.append(bytes(raw.data))
    return log_times, payloads


def _fast_poses(reader: BagReader, topic: str) -> TipSeries | None:
    """The poses by :mod:`~lumpbeam_ros.core.bagio.fastscan`, or ``None`` to decode one by one."""
    _, payloads = _fast_scan(reader, topic)
    decoded = fastscan.decode_pose_stamped(payloads)
    if decoded is None:
        return None  # not one layout (or a damaged message): the general decoder names it
    reader.report_loss(topic, len(payloads))
    ns, position, orientation, frame = decoded
    order = np.argsort(ns, kind='stable')
    pitch = convert.quaternions_to_pitch(orientation[order])
    return TipSeries(
        ns[order] / convert.NS_PER_S, position[order, 0], position[order, 2], pitch, frame_id=frame
    )


def read_floats(bag: Bag, topic: str) -> tuple[np.ndarray, np.ndarray]:
    """Reads a ``std_msgs/Float64`` topic as ``(log time s, value)`` arrays, sorted.

    Raises:
        BagError: Missing topic or another type (a message that does not decode is
            skipped and counted).
    """
    reader = open_bag(bag)
    reader.require(topic, 'std_msgs/msg/Float64')
    scanned = _fast_scan(reader, topic)
    values = fastscan.decode_float64(scanned[1])
    if values is not None:
        reader.report_loss(topic, len(scanned[1]))
        ns = np.asarray(scanned[0], dtype=np.int64)
        order = np.argsort(ns, kind='stable')
        return ns[order] / convert.NS_PER_S, values[order]
    rows = [
        (convert.ns_to_seconds(ns), float(msg.data))
        for ns, msg in reader.messages(topic, 'std_msgs/msg/Float64')
    ]
    t, value = _sorted_columns(rows, 2)
    return t, value


def read_load_events(bag: Bag, topic: str = TIP_LOAD) -> LoadSeries:
    """Reads ``/tip_load`` (kg at the tip, by log time); ``.changes()`` keeps the changes.

    Raises:
        BagError: Missing topic or another type (a message that does not decode is
            skipped and counted).
    """
    t, kg = read_floats(bag, topic)
    return LoadSeries(t, kg)


def read_points(bag: Bag, topic: str = TRACKER_POINT) -> PointSeries:
    """Reads a ``geometry_msgs/PointStamped`` topic, sorted by stamp.

    Raises:
        BagError: Missing topic, another type or mixed frames (a message that does not
            decode is skipped and counted).
    """
    return _vectors(bag, topic, POINT_STAMPED, convert.point_values)


def read_accelerations(bag: Bag, topic: str = TIP_IMU) -> PointSeries:
    """Reads the linear accelerations of a ``sensor_msgs/Imu`` topic (m/s^2), sorted by stamp.

    Raises:
        BagError: Missing topic, another type or mixed frames (a message that does not
            decode is skipped and counted).
    """
    return _vectors(bag, topic, IMU_TYPE, convert.imu_acceleration_values)


def _vectors(
    bag: Bag,
    topic: str,
    msgtype: str,
    decode: Callable[[Any], tuple[int, float, float, float, str]],
) -> PointSeries:
    """A topic of stamped 3-vectors, each message decoded to ``(ns, x, y, z, frame_id)``."""
    reader = open_bag(bag)
    decoded = (decode(m) for _, m in reader.messages(topic, msgtype))
    (t, x, y, z), frame = _stamped_columns(decoded, reader, topic)
    return PointSeries(t, x, y, z, frame)


def iter_images(bag: Bag, topic: str = IMAGE) -> Iterator[ImageFrame]:
    """Iterates over a ``sensor_msgs/Image`` topic in recording order.

    Yields:
        The frames; ``pixels`` is ``(h, w)`` for mono8 and ``(h, w, 3)`` otherwise.

    Raises:
        BagError: Missing topic, another type, an unsupported encoding or inconsistent sizes.
    """
    for _, msg in open_bag(bag).messages(topic, 'sensor_msgs/msg/Image'):
        pixels = convert.image_array(msg)
        yield ImageFrame(_stamp_s(msg), pixels, msg.encoding, msg.header.frame_id)


def read_camera_info(bag: Bag, topic: str = CAMERA_INFO) -> convert.CameraInfoData:
    """Returns the first ``sensor_msgs/CameraInfo`` of a topic.

    Raises:
        BagError: Missing or empty topic, or another type.
    """
    reader = open_bag(bag)
    for _, msg in reader.messages(topic, 'sensor_msgs/msg/CameraInfo'):
        return convert.camera_info_data(msg)
    raise BagError(f'{reader.path}: topic {topic} has no message')


def read_diagnostics(
    bag: Bag, topic: str = BEAM_PARAMS
) -> list[tuple[float, list[convert.Status]]]:
    """Reads a ``diagnostic_msgs/DiagnosticArray`` topic as ``(stamp s, statuses)`` pairs.

    Raises:
        BagError: Missing topic or another type (a message that does not decode is
            skipped and counted).
    """
    out = [
        (_stamp_s(msg), convert.diagnostic_statuses(msg))
        for _, msg in open_bag(bag).messages(topic, 'diagnostic_msgs/msg/DiagnosticArray')
    ]
    out.sort(key=lambda item: item[0])
    return out


class JointSeries(NamedTuple):
    """Joint angles (``/joint_states``): stamps ``t`` (s), ``angles`` (len(t), joints), names."""

    t: np.ndarray
    angles: np.ndarray
    names: tuple[str, ...]


def read_joint_states(bag: Bag, topic: str = JOINT_STATES) -> JointSeries:
    """Reads a ``sensor_msgs/JointState`` topic's positions, sorted by stamp.

    A stamp recorded twice keeps its first message, so the stamps increase strictly.

    Raises:
        BagError: Missing topic, another type, no message, or messages that name other
            joints than the first one (a message that does not decode is skipped and
            counted).
    """
    reader = open_bag(bag)
    reader.require(topic, JOINT_STATE_TYPE)
    stamps: list[float] = []
    rows: list[np.ndarray] = []
    names: tuple[str, ...] | None = None
    for _, msg in reader.messages(topic, JOINT_STATE_TYPE):
        ns, joint_names, positions = convert.joint_state_values(msg)
        if names is None:
            names = tuple(joint_names)
        if tuple(joint_names) != names or positions.size != len(names):
            raise BagError(
                f'{reader.path}: {topic} names joints {joint_names} with {positions.size} '
                f'positions after {list(names)}'
            )
        stamps.append(convert.ns_to_seconds(ns))
        rows.append(positions)
    if names is None:
        raise BagError(f'{reader.path}: topic {topic} has no message')
    t = np.asarray(stamps)
    order = np.argsort(t, kind='stable')
    # A message recorded twice (two recorders, a replayed bag) keeps its first copy: the
    # stamps of a joint series increase strictly.
    t, first = np.unique(t[order], return_index=True)
    return JointSeries(t, np.asarray(rows, dtype=float)[order][first], names)
