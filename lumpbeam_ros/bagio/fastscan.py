"""A fast path for reading one fixed-layout topic from an MCAP file.

The ``mcap`` reader merges every chunk's messages through a heap in log-time order and
builds a Python object per record: about 30 000 poses a second. Analysis only needs one topic
as columns, in any order (the series are sorted by stamp afterwards), so this module walks the
records with ``struct`` and hands back the raw message payloads; :func:`decode_pose_stamped`
then decodes a whole topic of equally long ``PoseStamped`` messages with one numpy view.

Anything unusual (a compression this module does not know, a cut file, messages of different
lengths) makes these functions return ``None``, and the caller takes the general reader, which
handles every case with its warnings and errors.
"""

from __future__ import annotations

import struct
from pathlib import Path

import numpy as np

MAGIC = b'\x89MCAP0\r\n'
_OP_FOOTER, _OP_CHANNEL, _OP_MESSAGE, _OP_CHUNK, _OP_DATA_END = 0x02, 0x04, 0x05, 0x06, 0x0F
_RECORD = struct.Struct('<BQ')
_CHUNK_HEADER = struct.Struct('<QQQI')
_MESSAGE_HEADER = struct.Struct('<HIQQ')

#: CDR encapsulation of little-endian plain CDR, as ROS 2 writes it.
_CDR_LE = b'\x00\x01\x00\x00'


def _string(buffer: memoryview, offset: int) -> tuple[str, int]:
    (length,) = struct.unpack_from('<I', buffer, offset)
    start = offset + 4
    return bytes(buffer[start : start + length]).decode(), start + length


def _decompress(compression: str, data: memoryview, size: int) -> memoryview | None:
    if compression == '':
        return data
    if compression == 'zstd':
        import zstandard

        return memoryview(zstandard.ZstdDecompressor().decompress(data, max_output_size=size))
    if compression == 'lz4':
        import lz4.frame

        return memoryview(lz4.frame.decompress(data))
    return None


class _Scan:
    """The payloads of one topic's messages, collected record by record."""

    def __init__(self, topic: str):
        self.topic = topic
        self.channels: set[int] = set()
        self.log_times: list[int] = []
        self.payloads: list[bytes] = []

    def records(self, buffer: memoryview, start: int, end: int) -> bool:
        """Walks records in ``buffer[start:end]``; False at anything it cannot read."""
        offset = start
        while offset < end:
            if end - offset < _RECORD.size:
                return False
            opcode, length = _RECORD.unpack_from(buffer, offset)
            body = offset + _RECORD.size
            offset = body + length
            if offset > end:
                return False
            if opcode == _OP_MESSAGE:
                channel, _, log_time, _ = _MESSAGE_HEADER.unpack_from(buffer, body)
                if channel in self.channels:
                    self.log_times.append(log_time)
                    self.payloads.append(bytes(buffer[body + _MESSAGE_HEADER.size : offset]))
            elif opcode == _OP_CHANNEL:
                channel_id = struct.unpack_from('<H', buffer, body)[0]
                name, _ = _string(buffer, body + 4)
                if name == self.topic:
                    self.channels.add(channel_id)
            elif opcode == _OP_CHUNK:
                if not self.chunk(buffer, body, offset):
                    return False
            elif opcode in (_OP_DATA_END, _OP_FOOTER):
                return True
        return True

    def chunk(self, buffer: memoryview, start: int, end: int) -> bool:
        _, _, size, _ = _CHUNK_HEADER.unpack_from(buffer, start)
        compression, offset = _string(buffer, start + _CHUNK_HEADER.size)
        (length,) = struct.unpack_from('<Q', buffer, offset)
        data = buffer[offset + 8 : offset + 8 + length]
        records = _decompress(compression, data, size)
        return records is not None and self.records(records, 0, len(records))


def scan_topic(file: str | Path, topic: str) -> tuple[list[int], list[bytes]] | None:
    """Returns the serialized messages of one topic in an MCAP file, in file order.

    Args:
        file: The ``.mcap`` file.
        topic: The topic.

    Returns:
        The log times (ns) and payloads (CDR), or ``None`` when the file holds anything this
        fast path does not read (the general reader then takes over).
    """
    data = Path(file).read_bytes()
    if not data.startswith(MAGIC):
        return None
    scan = _Scan(topic)
    buffer = memoryview(data)
    try:
        complete = scan.records(buffer, len(MAGIC), len(buffer))
    except (struct.error, UnicodeDecodeError, ValueError):
        return None
    return (scan.log_times, scan.payloads) if complete else None


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
