"""Fast paths beside the general readers: fixed-layout topics and MCAP Message records.

The general decoder (rosbags' CDR deserializer, :func:`~lumpbeam_ros.core.bagio.typestore.
deserialize`) builds a Python object per message: about 30 000 poses a second. Analysis only
needs one topic as columns, so :func:`decode_pose_stamped` decodes a whole topic of equally
long ``PoseStamped`` messages (one frame id throughout) with one numpy view, and
:func:`decode_float64` a ``Float64`` topic. The payloads are those the bag reader verified
(:class:`~lumpbeam_ros.core.bagio.reader.BagReader`); anything unusual (another layout, another
frame, a damaged message) makes them return ``None``, and the caller decodes message by
message, which skips and counts what does not decode. ``lumpbeam bench`` times the two
(``analyze_bag_throughput``).

:func:`message_record` reads an MCAP Message record's fields in place and copies its data
once, where mcap's own reader copies it three times through streams: an image's megabyte a
frame. The bag reader uses it for every Message record long enough to hold its fields.
"""

from __future__ import annotations

import mmap
import struct

import numpy as np
from mcap.records import Message

#: CDR encapsulation of little-endian plain CDR, as ROS 2 writes it.
_CDR_LE = b'\x00\x01\x00\x00'
#: A Message record's fields before its data: channel id, sequence, log and publish times.
_MESSAGE_FIELDS = struct.Struct('<HIQQ')


def message_record(data: bytes | mmap.mmap, start: int, stop: int) -> Message | None:
    """The MCAP Message record whose content is ``data[start:stop]``, as mcap reads it.

    Args:
        data: The bytes (a file's map, or a chunk's records).
        start: Where the record's content starts (after its opcode and length).
        stop: Where it ends.

    Returns:
        The record, or ``None`` when the content is too short to hold the fields (mcap's
        reader then says why).
    """
    if stop - start < _MESSAGE_FIELDS.size:
        return None
    channel_id, sequence, log_time, publish_time = _MESSAGE_FIELDS.unpack_from(data, start)
    return Message(
        channel_id=channel_id,
        sequence=sequence,
        log_time=log_time,
        publish_time=publish_time,
        data=bytes(data[start + _MESSAGE_FIELDS.size : stop]),
    )


def decode_pose_stamped(
    payloads: list[bytes],
) -> tuple[np.ndarray, np.ndarray, np.ndarray, str] | None:
    """Decodes equally long ``geometry_msgs/PoseStamped`` CDR messages in one go.

    Args:
        payloads: Serialized messages (little-endian CDR, one frame_id throughout).

    Returns:
        ``(stamp_ns, position (n, 3), orientation xyzw (n, 4), frame_id)``, or ``None`` when
        the messages are not of one layout (the general decoder then takes over).
    """
    if not payloads:
        return None
    size = len(payloads[0])
    first = payloads[0]
    if size < 16 or first[:4] != _CDR_LE or any(len(p) != size for p in payloads):
        return None
    (name_length,) = struct.unpack_from('<I', first, 12)
    name_end = 16 + name_length
    # CDR aligns the float64s to 8 bytes, counted from after the encapsulation header.
    poses_at = 4 + -(-(name_end - 4) // 8) * 8
    if poses_at + 56 != size:
        return None
    rows = np.frombuffer(b''.join(payloads), dtype=np.uint8).reshape(len(payloads), size)
    if not np.all(rows[:, 12:name_end] == rows[0, 12:name_end]):
        return None  # frames differ: let the general reader name them
    seconds = rows[:, 4:8].copy().view('<i4')[:, 0].astype(np.int64)
    nanoseconds = rows[:, 8:12].copy().view('<u4')[:, 0].astype(np.int64)
    values = rows[:, poses_at:].copy().view('<f8')
    frame_id = bytes(first[16 : name_end - 1]).decode()
    return seconds * 1_000_000_000 + nanoseconds, values[:, :3], values[:, 3:], frame_id


def decode_float64(payloads: list[bytes]) -> np.ndarray | None:
    """Decodes ``std_msgs/Float64`` CDR messages in one go (``None``: not of that layout)."""
    if not payloads or any(len(p) != 12 or p[:4] != _CDR_LE for p in payloads):
        return None
    return (
        np.frombuffer(b''.join(payloads), dtype=np.uint8)
        .reshape(-1, 12)[:, 4:]
        .copy()
        .view('<f8')[:, 0]
    )
