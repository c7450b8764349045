"""Writing rosbag2 bags (MCAP storage, CDR) that survive a crash of their writer.

rosbags' :class:`~rosbags.rosbag2.Writer` writes MCAP in chunks of ~1 MiB and writes
``metadata.yaml`` only in ``close()``, so a writer killed mid-recording would leave a bag that
no reader opens and up to a whole chunk (minutes of poses) only in memory. :class:`BagWriter`
adds what a recorder needs on top of it:

- ``metadata.yaml`` is written when the bag is created and refreshed at every flush;
- a flush, at most ``flush_period_s`` after a message arrives, closes the pending chunk and
  hands it to the OS; a SIGKILL then loses at most the messages since the last flush, and
  every chunk before it stays readable (:mod:`lumpbeam_ros.bagio.reader` reads a file
  without its closing index, with a warning);
- an I/O error (disk full, file too large) raises :class:`~lumpbeam_ros.errors.BagError`
  after refreshing the metadata, so what was flushed stays readable;
- messages are in log-time order within the file, as MCAP readers (``mcap doctor``, players
  that merge chunks) expect: the messages written since the last flush are held and go to
  the file sorted by log time (ties in the order they were written). A message older than
  what an earlier flush wrote cannot be put in order any more: it is written with a warning,
  so a writer whose sources are out of order merges them first.

Messages' log time is the recording time; for synthetic bags it equals the header stamp
(doc/interfaces.md, 'Frames, units and time': stamps are measurement time).
"""

from __future__ import annotations

import logging
import operator
import time
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from rosbags.interfaces import Connection, Qos
from rosbags.rosbag2 import StoragePlugin, Writer, WriterError

from lumpbeam_ros.bagio import convert, metadata
from lumpbeam_ros.bagio.qos import default_profile
from lumpbeam_ros.bagio.typestore import serialize, type_description
from lumpbeam_ros.closing import ClosedOnExit
from lumpbeam_ros.errors import BagError
from lumpbeam_ros.interface import BASE_FRAME, CAMERA_FRAME, CLOCK

_log = logging.getLogger(__name__)

#: Bytes of pending messages that trigger a flush (rosbags closes its chunks at 1 MiB too).
PENDING_LIMIT_BYTES = 1 << 20


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
        self._writer = Writer(
            self.path, version=metadata.VERSION, storage_plugin=StoragePlugin.MCAP
        )
        try:
            self._writer.open()
        except WriterError as exc:
            raise BagError(str(exc)) from None
        except OSError as exc:
            raise BagError(f'cannot create bag {self.path}: {exc.strerror or exc}') from None
        self._connections: dict[str, Connection] = {}
        self._qos: dict[str, list[Qos]] = {}
        self._failed = False
        self._closed = False
        # Messages since the last flush: (log time, sequence, connection, data).
        self._pending: list[tuple[int, int, Connection, bytes | memoryview]] = []
        self._pending_bytes = 0
        self._sequence = 0
        self._flushed_log_time = -1  # the latest log time in the file
        self._warned_order = False
        self._last_flush = time.monotonic()
        self._flushed_snapshot = self._metadata()
        self._guard(self._flush_storage)  # the MCAP magic and header, so the file is one
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
        if not topic.startswith('/') or topic in self._connections:
            problem = 'is declared twice' if topic in self._connections else 'must start with /'
            raise BagError(f'topic {topic!r} {problem}')
        if msgdef is None or type_hash is None:
            known_def, known_hash = type_description(msgtype)
            msgdef = known_def if msgdef is None else msgdef
            type_hash = known_hash if type_hash is None else type_hash
        profiles = list(qos) if qos is not None else [default_profile(topic, msgtype)]
        self._check_open()
        self._connections[topic] = self._guard(
            lambda: self._writer.add_connection(
                topic, msgtype, msgdef=msgdef, rihs01=type_hash, offered_qos_profiles=profiles
            )
        )
        self._qos[topic] = profiles

    def has_topic(self, topic: str) -> bool:
        """Tells whether a topic has been declared."""
        return topic in self._connections

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
        connection = self._connections.get(topic)
        if connection is None:
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
        self._pending.append((int(log_time_ns), self._sequence, connection, held))
        self._sequence += 1
        self._pending_bytes += len(data)
        if (
            self._pending_bytes >= PENDING_LIMIT_BYTES
            or time.monotonic() - self._last_flush >= self._flush_period
        ):
            self.flush()

    def write_message(self, topic: str, message: Any, log_time_ns: int) -> None:
        """Serializes and writes a rosbags message, declaring its topic on first use.

        Args:
            topic: Topic name.
            message: An instance of a typestore class (see :mod:`~lumpbeam_ros.bagio.convert`).
            log_time_ns: Recording time, ns.

        Raises:
            BagError: As :meth:`write_raw`, or a topic declared with another type.
        """
        msgtype = message.__msgtype__
        if topic not in self._connections:
            self.add_topic(topic, msgtype)
        elif self._connections[topic].msgtype != msgtype:
            declared = self._connections[topic].msgtype
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

    def write_image(
        self,
        topic: str,
        stamp: float,
        pixels: np.ndarray,
        frame: str = CAMERA_FRAME,
        encoding: str | None = None,
    ) -> None:
        """Writes a ``sensor_msgs/msg/Image``; see :func:`~lumpbeam_ros.bagio.convert.image`."""
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
        return sum(self._writer.counts.values()) + len(self._pending)

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
        self._guard(self._flush_storage)
        self._flushed_snapshot = self._metadata()
        self._guard(lambda: metadata.write(self.path, self._flushed_snapshot))
        self._last_flush = time.monotonic()

    def close(self) -> None:
        """Writes the MCAP summary and the final ``metadata.yaml``; idempotent.

        Raises:
            BagError: An I/O error (the flushed part stays readable).
        """
        if self._closed or self._failed:
            return
        self._guard(self._write_pending)
        self._guard(self._writer.close)
        self._closed = True

    # -- internals --------------------------------------------------------------------------

    def _write_pending(self) -> None:
        """Hands the pending messages to the MCAP writer in log-time order."""
        pending, self._pending, self._pending_bytes = self._pending, [], 0
        pending.sort(key=operator.itemgetter(0, 1))
        for log_time, _, connection, data in pending:
            self._writer.write(connection, log_time, data)
        if pending:
            self._flushed_log_time = max(self._flushed_log_time, pending[-1][0])

    def _flush_storage(self) -> None:
        # rosbags' McapWriter exposes its pending chunk and file object as public attributes;
        # closing the chunk early is what its own writer does once a chunk passes 1 MiB.
        storage = self._writer.storage
        assert storage is not None
        if storage.chunk.bio.tell():  # type: ignore[attr-defined]
            storage.close_chunk()  # type: ignore[attr-defined]
        storage.bio.flush()  # type: ignore[attr-defined]

    def _metadata(self) -> dict[str, Any]:
        w = self._writer
        topics = [
            (c.topic, c.msgtype, w.counts[c.id], self._qos[c.topic], c.digest)
            for c in self._connections.values()
        ]
        data_file = f'{self.path.name}.mcap'
        return metadata.build(data_file, topics, w.min_timestamp, w.max_timestamp)

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
            self._writer.abort()
            kept = self._flushed_snapshot['rosbag2_bagfile_information']['message_count']
            raise BagError(
                f'writing {self.path} failed ({exc.strerror or exc}); '
                f'the {kept} messages flushed before are kept'
            ) from None
