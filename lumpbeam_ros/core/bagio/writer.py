"""Writing rosbag2 bags (MCAP storage, CDR) that survive a crash of their writer.

The MCAP file is written by the ``mcap`` package's :class:`~mcap.writer.Writer` with every
integrity check MCAP has: a CRC-32 of each chunk's records, of the data section and of the
summary, so that a reader (this package's, rosbags', the mcap tools) tells damaged bytes from
data. :class:`BagWriter` adds what a rosbag2 recorder needs on top of it:

- ``metadata.yaml`` is written when the bag is created and refreshed at every flush;
- a flush, at most ``flush_period_s`` after a message arrives, closes the pending chunk and
  hands it to the OS; a SIGKILL then loses at most the messages since the last flush, and
  every chunk before it stays readable (:mod:`lumpbeam_ros.core.bagio.reader` reads a file
  without its closing index, with a warning);
- an I/O error (disk full, file too large) raises :class:`~lumpbeam_ros.base.errors.BagError`
  after refreshing the metadata, so what was flushed stays readable;
- messages are in log-time order within the file, as MCAP readers (``mcap doctor``, players
  that merge chunks) expect: the messages written since the last flush are held and go to
  the file sorted by log time (ties in the order they were written). A message older than
  what an earlier flush wrote cannot be put in order any more: it is written with a warning,
  so a writer whose sources are out of order merges them first.

The file is what ``ros2 bag record -s mcap`` writes: the ``ros2`` profile, one ``ros2msg``
schema per type, one ``cdr`` channel per topic with its offered QoS in the channel metadata,
uncompressed chunks (a 180 fps camera stream does not wait for a compressor) and the
``rosbag2`` metadata record at the end.

Messages' log time is the recording time; for synthetic bags it equals the header stamp
(doc/interfaces.md, 'Frames, units and time': stamps are measurement time).
"""

from __future__ import annotations

import logging
import operator
import shutil
import time
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

import numpy as np
import yaml
from mcap.writer import CompressionType
from mcap.writer import Writer as McapWriter
from rosbags.interfaces import Qos

from lumpbeam_ros import __version__
from lumpbeam_ros.base.closing import ClosedOnExit
from lumpbeam_ros.base.errors import BagError, LumpbeamError
from lumpbeam_ros.base.interface import BASE_FRAME, CAMERA_FRAME, CLOCK
from lumpbeam_ros.core.bagio import convert, metadata
from lumpbeam_ros.core.bagio.qos import default_profile
from lumpbeam_ros.core.bagio.typestore import serialize, type_description

_log = logging.getLogger(__name__)

#: Bytes of pending messages that trigger a flush (a chunk of about 1 MiB, as rosbag2 writes).
PENDING_LIMIT_BYTES = 1 << 20
#: Log time a chunk spans at most, ns (but for messages that arrive later than this): a
#: damaged chunk fails its CRC whole, so this bounds what one damaged spot costs a reader,
#: whether the bag is recorded live (flushed every ``flush_period_s``) or written offline.
CHUNK_SPAN_NS = 500_000_000


@dataclass(frozen=True)
class _Topic:
    """A declared topic: its MCAP channel and what ``metadata.yaml`` lists of it."""

    name: str
    msgtype: str
    channel_id: int
    qos: list[Qos]
    type_hash: str


def replace_bags(path: str | Path) -> None:
    """Removes a bag, or a folder of bags, so that it can be written anew (``--force``).

    Nothing else is ever removed: a folder that is neither is refused.

    Args:
        path: The bag folder, or a folder whose every entry is a bag folder; nothing happens
            when it does not exist.

    Raises:
        LumpbeamError: ``path`` is something else (a file, a folder with other things in it).
    """
    path = Path(path)
    if not path.exists():
        return
    bags = path.is_dir() and (
        metadata.is_bag(path) or all(metadata.is_bag(entry) for entry in path.iterdir())
    )
    if not bags:
        raise LumpbeamError(
            f'{path} exists and is not a bag (or a folder of bags): --force replaces bags only'
        )
    shutil.rmtree(path)


class BagWriter(ClosedOnExit):
    """A new rosbag2 bag, written message by message.

    Use as a context manager (closing writes the MCAP summary and the final metadata)::

        with BagWriter('out/drop') as bag:
            bag.write_pose('/tip_pose', 0.0, 2.31, -0.05, 0.03)
            bag.write_float('/tip_load', 0.0, 4.5)

    Args:
        path: The bag folder to create; it must not exist (a bag is never overwritten).
        flush_period_s: Longest time a written message may stay in memory, s.

    Raises:
        BagError: The folder exists or cannot be created.
    """

    def __init__(self, path: str | Path, flush_period_s: float = 0.5):
        self.path = Path(path)
        if self.path.exists():
            raise BagError(f'{self.path} exists already; a bag is never overwritten')
        if not flush_period_s > 0.0:
            raise BagError(f'flush period must be positive, got {flush_period_s!r}')
        self._flush_period = flush_period_s
        try:
            self.path.mkdir(parents=True)
            self._file: IO[bytes] = (self.path / f'{self.path.name}.mcap').open('xb')
        except OSError as exc:
            raise BagError(f'cannot create bag {self.path}: {exc.strerror or exc}') from None
        self._mcap = McapWriter(
            self._file,
            chunk_size=PENDING_LIMIT_BYTES,
            compression=CompressionType.NONE,
            enable_crcs=True,
            enable_data_crcs=True,
        )
        self._topics: dict[str, _Topic] = {}
        self._schemas: dict[str, int] = {}
        self._counts: dict[str, int] = {}
        self._start_ns = 2**63 - 1
        self._end_ns = 0
        self._failed = False
        self._closed = False
        # Messages since the last flush: (log time, sequence, topic, data).
        self._pending: list[tuple[int, int, _Topic, bytes | memoryview]] = []
        self._pending_bytes = 0
        self._sequence = 0
        self._flushed_log_time = -1  # the latest log time in the file
        self._warned_order = False
        self._last_flush = time.monotonic()
        self._flushed_snapshot = self._metadata()
        library = f'lumpbeam_ros {__version__}'
        self._guard(lambda: self._mcap.start(profile='ros2', library=library))
        self._guard(self._mcap.flush)  # the MCAP magic and header, so the file is one
        self._guard(lambda: metadata.write(self.path, self._flushed_snapshot))

    # -- topics and raw messages ------------------------------------------------------------

    def add_topic(
        self,
        topic: str,
        msgtype: str,
        qos: Sequence[Qos] | None = None,
        msgdef: str | None = None,
        type_hash: str | None = None,
    ) -> None:
        """Declares a topic before its first message.

        Args:
            topic: Topic name, absolute (``'/tip_pose'``).
            msgtype: Full type name, e.g. ``'geometry_msgs/msg/PoseStamped'``.
            qos: Offered QoS profiles; the project's default for the topic when ``None``.
            msgdef: ``ros2msg`` definition text; taken from the Jazzy typestore when ``None``.
            type_hash: RIHS01 hash; from the typestore when ``None``.

        Raises:
            BagError: A topic declared twice, a bad name, or a type neither known nor described.
        """
        if not topic.startswith('/') or topic in self._topics:
            problem = 'is declared twice' if topic in self._topics else 'must start with /'
            raise BagError(f'topic {topic!r} {problem}')
        if msgdef is None or type_hash is None:
            known_def, known_hash = type_description(msgtype)
            msgdef = known_def if msgdef is None else msgdef
            type_hash = known_hash if type_hash is None else type_hash
        profiles = list(qos) if qos is not None else [default_profile(topic, msgtype)]
        self._check_open()
        schema_id = self._schemas.get(msgtype)
        if schema_id is None:
            # rosbag2 tells the two definition languages apart by the IDL separator line.
            encoding = 'ros2idl' if msgdef.startswith('=' * 80 + '\nIDL: ') else 'ros2msg'
            schema_id = self._guard(
                lambda: self._mcap.register_schema(msgtype, encoding, msgdef.encode())
            )
            self._schemas[msgtype] = schema_id
        qos_text = yaml.safe_dump(metadata.dump_qos(profiles), default_flow_style=False).strip()
        channel_id = self._guard(
            lambda: self._mcap.register_channel(
                topic, 'cdr', schema_id, {'offered_qos_profiles': qos_text}
            )
        )
        self._topics[topic] = _Topic(topic, msgtype, channel_id, profiles, type_hash)
        self._counts[topic] = 0

    def has_topic(self, topic: str) -> bool:
        """Tells whether a topic has been declared."""
        return topic in self._topics

    def write_raw(self, topic: str, log_time_ns: int, data: bytes | memoryview) -> None:
        """Writes one serialized (CDR) message of a declared topic.

        Args:
            topic: A topic declared with :meth:`add_topic`.
            log_time_ns: Recording time, ns since the epoch.
            data: The CDR bytes.

        A log time before what an earlier flush wrote is written all the same, with a
        warning (once per bag): the file is then out of log-time order.

        Raises:
            BagError: Undeclared topic, a closed bag, or an I/O error (what was flushed before
                stays readable).
        """
        declared = self._topics.get(topic)
        if declared is None:
            raise BagError(f'topic {topic!r} was not declared in {self.path}')
        if log_time_ns < 0:
            raise BagError(f'log time must be >= 0 ns, got {log_time_ns}')
        if log_time_ns < self._flushed_log_time and not self._warned_order:
            self._warned_order = True
            _log.warning(
                '%s: %s message logged at %d ns comes after one logged at %d ns was flushed; '
                'the file is out of log-time order from here (write in log-time order, give '
                'or take one flush period)',
                self.path,
                topic,
                log_time_ns,
                self._flushed_log_time,
            )
        self._check_open()
        # Held until the next flush: a view into a buffer its owner reuses must be copied.
        held = bytes(data) if isinstance(data, memoryview) else data
        self._pending.append((int(log_time_ns), self._sequence, declared, held))
        self._sequence += 1
        self._pending_bytes += len(data)
        if (
            self._pending_bytes >= PENDING_LIMIT_BYTES
            or time.monotonic() - self._last_flush >= self._flush_period
        ):
            self.flush()
        elif log_time_ns - self._pending[0][0] >= 2 * CHUNK_SPAN_NS:
            # An offline writer outpaces the flush period: a chunk per CHUNK_SPAN_NS of log
            # time, keeping the newest span pending so that what comes late still sorts in.
            self._guard(lambda: self._write_pending(before=log_time_ns - CHUNK_SPAN_NS))
            self._guard(self._mcap.flush)
            self._refresh_metadata()

    def write_message(self, topic: str, message: Any, log_time_ns: int) -> None:
        """Serializes and writes a rosbags message, declaring its topic on first use.

        Args:
            topic: Topic name.
            message: An instance of a typestore class (see
                :mod:`~lumpbeam_ros.core.bagio.convert`).
            log_time_ns: Recording time, ns.

        Raises:
            BagError: As :meth:`write_raw`, or a topic declared with another type.
        """
        msgtype = message.__msgtype__
        if topic not in self._topics:
            self.add_topic(topic, msgtype)
        elif self._topics[topic].msgtype != msgtype:
            declared = self._topics[topic].msgtype
            raise BagError(f'topic {topic} carries {declared}, not {msgtype}')
        self.write_raw(topic, log_time_ns, serialize(message))

    # -- typed helpers (stamp = measurement time, s; log time = stamp) -------------------------

    def write_pose(
        self, topic: str, stamp: float, x: float, z: float, pitch: float, frame: str = BASE_FRAME
    ) -> None:
        """Writes a planar tip pose as ``geometry_msgs/msg/PoseStamped`` (y = 0).

        Args:
            topic: E.g. ``'/tip_pose'``.
            stamp: Measurement time, s.
            x: Tip position along the beam, m.
            z: Vertical tip position, m.
            pitch: Rotation about +y, rad (positive when the tip bends down).
            frame: ``header.frame_id``.
        """
        ns = convert.seconds_to_ns(stamp)
        self.write_message(topic, convert.pose_stamped(ns, x, z, pitch, frame), ns)

    def write_float(self, topic: str, stamp: float, value: float) -> None:
        """Writes a ``std_msgs/msg/Float64`` (e.g. ``/tip_load`` in kg) logged at ``stamp`` s."""
        ns = convert.seconds_to_ns(stamp)
        self.write_message(topic, convert.float64(value), ns)

    def write_joint_state(
        self, topic: str, stamp: float, names: Iterable[str], positions: np.ndarray
    ) -> None:
        """Writes a ``sensor_msgs/msg/JointState`` of joint angles (e.g. ``/joint_states``)."""
        ns = convert.seconds_to_ns(stamp)
        self.write_message(topic, convert.joint_state(ns, names, positions), ns)

    def write_point(
        self, topic: str, stamp: float, x: float, y: float, z: float, frame: str
    ) -> None:
        """Writes a ``geometry_msgs/msg/PointStamped`` (e.g. ``/tracker/point``)."""
        ns = convert.seconds_to_ns(stamp)
        self.write_message(topic, convert.point_stamped(ns, x, y, z, frame), ns)

    def write_acceleration(
        self, topic: str, stamp: float, acceleration: tuple[float, float, float], frame: str
    ) -> None:
        """Writes a ``sensor_msgs/msg/Imu`` of a linear acceleration, m/s^2 (``/tip_imu``)."""
        ns = convert.seconds_to_ns(stamp)
        self.write_message(topic, convert.imu_acceleration(ns, acceleration, frame), ns)

    def write_image(
        self,
        topic: str,
        stamp: float,
        pixels: np.ndarray,
        frame: str = CAMERA_FRAME,
        encoding: str | None = None,
    ) -> None:
        """Writes a ``sensor_msgs/msg/Image`` (:func:`~lumpbeam_ros.core.bagio.convert.image`)."""
        ns = convert.seconds_to_ns(stamp)
        self.write_message(topic, convert.image(ns, pixels, frame, encoding), ns)

    def write_camera_info(self, topic: str, stamp: float, info: convert.CameraInfoData) -> None:
        """Writes a ``sensor_msgs/msg/CameraInfo``."""
        ns = convert.seconds_to_ns(stamp)
        self.write_message(topic, convert.camera_info(ns, info), ns)

    def write_diagnostics(
        self, topic: str, stamp: float, statuses: Iterable[convert.Status], frame: str = ''
    ) -> None:
        """Writes a ``diagnostic_msgs/msg/DiagnosticArray`` (e.g. ``/beam_params``)."""
        ns = convert.seconds_to_ns(stamp)
        self.write_message(topic, convert.diagnostic_array(ns, statuses, frame), ns)

    def write_clock(self, stamp: float, topic: str = CLOCK) -> None:
        """Writes a ``rosgraph_msgs/msg/Clock``."""
        ns = convert.seconds_to_ns(stamp)
        self.write_message(topic, convert.clock(ns), ns)

    # -- durability -------------------------------------------------------------------------

    @property
    def message_count(self) -> int:
        """Messages written so far (flushed or pending)."""
        return sum(self._counts.values()) + len(self._pending)

    @property
    def flushed_log_time_ns(self) -> int:
        """The latest log time already in the file (-1 before the first flush), ns."""
        return self._flushed_log_time

    def flush(self) -> None:
        """Puts every message written so far into the file and refreshes ``metadata.yaml``.

        A recorder calls it on a timer too, so the last messages before a quiet spell reach
        the disk without waiting for the next message. Nothing happens when nothing is pending.

        Raises:
            BagError: An I/O error.
        """
        self._check_open()
        if not self._pending:
            return
        self._guard(self._write_pending)
        self._guard(self._mcap.flush)
        self._refresh_metadata()
        self._last_flush = time.monotonic()

    def close(self) -> None:
        """Writes the MCAP summary and the final ``metadata.yaml``; idempotent.

        Raises:
            BagError: An I/O error (the flushed part stays readable).
        """
        if self._closed or self._failed:
            return
        self._guard(self._write_pending)
        final = self._metadata()
        info = yaml.safe_dump(final['rosbag2_bagfile_information'], sort_keys=False)
        # rosbag2's MCAP storage keeps a copy of the metadata in the file itself.
        self._guard(lambda: self._mcap.add_metadata('rosbag2', {'serialized_metadata': info}))
        self._guard(self._mcap.finish)
        self._guard(self._file.close)
        self._guard(lambda: metadata.write(self.path, final))
        self._closed = True

    # -- internals --------------------------------------------------------------------------

    def _write_pending(self, before: int | None = None) -> None:
        """Hands the pending messages (logged before ``before`` ns) to the MCAP writer, sorted."""
        self._pending.sort(key=operator.itemgetter(0, 1))
        split = len(self._pending)
        if before is not None:
            split = next((i for i, m in enumerate(self._pending) if m[0] >= before), split)
        pending, self._pending = self._pending[:split], self._pending[split:]
        self._pending_bytes = sum(len(m[3]) for m in self._pending)
        chunk_start = pending[0][0] if pending else 0
        for log_time, _, topic, data in pending:
            if log_time - chunk_start >= CHUNK_SPAN_NS:
                # Closes the chunk: none spans more than CHUNK_SPAN_NS of log time.
                self._mcap.flush()  # type: ignore[no-untyped-call]
                chunk_start = log_time
            self._mcap.add_message(topic.channel_id, log_time, bytes(data), log_time)
            self._counts[topic.name] += 1
            self._start_ns = min(self._start_ns, log_time)
            self._end_ns = max(self._end_ns, log_time)
        if pending:
            self._flushed_log_time = max(self._flushed_log_time, pending[-1][0])

    def _refresh_metadata(self) -> None:
        """Writes ``metadata.yaml`` for what the file holds now."""
        self._flushed_snapshot = self._metadata()
        self._guard(lambda: metadata.write(self.path, self._flushed_snapshot))

    def _metadata(self) -> dict[str, Any]:
        topics = [
            (t.name, t.msgtype, self._counts[t.name], t.qos, t.type_hash)
            for t in self._topics.values()
        ]
        data_file = f'{self.path.name}.mcap'
        return metadata.build(data_file, topics, self._start_ns, self._end_ns)

    def _check_open(self) -> None:
        if self._failed:
            raise BagError(f'{self.path}: writing stopped after an earlier error')
        if self._closed:
            raise BagError(f'{self.path} is closed')

    def _guard(self, action: Any) -> Any:
        """Runs a storage action; an I/O error closes the bag, keeping what was flushed."""
        try:
            return action()
        except OSError as exc:
            self._failed = True
            try:
                metadata.write(self.path, self._flushed_snapshot)
            except OSError:
                pass  # the metadata of the previous flush is already on disk
            try:
                self._file.close()
            except OSError:
                pass  # the buffer that failed to go out is lost either way
            kept = self._flushed_snapshot['rosbag2_bagfile_information']['message_count']
            raise BagError(
                f'writing {self.path} failed ({exc.strerror or exc}); '
                f'the {kept} messages flushed before are kept'
            ) from None
