"""Reading rosbag2 bags with MCAP storage, including bags whose recording was cut.

A complete MCAP file ends with a summary (chunk indexes), which lets the reader fetch one
topic without decoding the others. A file whose writer was killed has no summary: the reader
then walks the chunks from the start and stops, with a warning, at the first incomplete
record, so everything that reached the disk is read.
"""

from __future__ import annotations

import logging
import struct
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any, BinaryIO

from mcap.exceptions import McapError
from mcap.reader import SeekingReader
from mcap.records import Channel, Message, Schema
from mcap.stream_reader import StreamReader

from lumpbeam_ros.bagio import metadata
from lumpbeam_ros.bagio.typestore import deserialize
from lumpbeam_ros.errors import BagError

_log = logging.getLogger(__name__)

# What the mcap package raises on a short or malformed file.
_READ_ERRORS = (McapError, struct.error, EOFError, ValueError, IndexError)


@dataclass(frozen=True)
class RawMessage:
    """One serialized message.

    Attributes:
        topic: Topic name.
        msgtype: Full type name.
        log_time_ns: Recording time, ns.
        data: CDR bytes.
    """

    topic: str
    msgtype: str
    log_time_ns: int
    data: bytes | memoryview


class BagReader:
    """A rosbag2 bag opened for reading.

    Args:
        path: The bag folder.

    Raises:
        BagError: Not a bag, unreadable metadata, a missing, empty or non-MCAP data file.

    Attributes:
        path: The bag folder.
        info: The parsed ``metadata.yaml``.
        truncated: Data files without their closing summary (read as far as they go).
    """

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.info = metadata.load(self.path)
        self.truncated: list[Path] = []
        for file in self.info.files:
            if self._probe(file) is None:
                self.truncated.append(file)
                _log.warning(
                    '%s: %s has no closing index (recording was cut?); reading what is '
                    'readable. `lumpbeam repair %s` makes it whole for every reader',
                    self.path,
                    file.name,
                    self.path,
                )

    @property
    def topics(self) -> dict[str, metadata.TopicEntry]:
        """The topics the metadata lists, by name."""
        return self.info.topics

    def require(self, topic: str, msgtype: str | None = None) -> metadata.TopicEntry:
        """Returns a topic's entry after checking that it exists and has the expected type.

        Raises:
            BagError: The topic is missing or has another type.
        """
        entry = self.topics.get(topic)
        if entry is None:
            listed = ', '.join(sorted(self.topics)) or 'none'
            raise BagError(f'{self.path}: no topic {topic} (topics: {listed})')
        if msgtype is not None and entry.msgtype != msgtype:
            raise BagError(f'{self.path}: topic {topic} has type {entry.msgtype}, not {msgtype}')
        return entry

    def iter_raw(self, topics: Iterable[str] | None = None) -> Iterator[RawMessage]:
        """Iterates over serialized messages, in log-time order within each data file.

        Args:
            topics: Topics to read; all when ``None``.

        Yields:
            The messages.
        """
        for schema, channel, message in self.iter_records(topics):
            yield _raw(schema, channel, message)

    def iter_records(
        self,
        topics: Iterable[str] | None = None,
        declared: dict[str, tuple[Schema | None, Channel]] | None = None,
    ) -> Iterator[tuple[Schema | None, Channel, Message]]:
        """Iterates over the MCAP records of the messages, with their schema and channel.

        What :meth:`iter_raw` reads, with what a copy of the bag needs besides (the schema's
        message definition, the channel's metadata). A read that comes up short of the
        metadata's counts warns (:meth:`check_count`).

        Args:
            topics: Topics to read; all when ``None``.
            declared: Filled, when given, with the schema and channel of every topic the data
                files declare, messages or not (as :func:`stream_messages` fills it).

        Yields:
            ``(schema, channel, message)``, in log-time order within each data file.
        """
        wanted = None if topics is None else set(topics)
        read = dict.fromkeys(self.topics if wanted is None else wanted, 0)
        for file in self.info.files:
            with file.open('rb') as stream:
                if file in self.truncated:
                    messages = stream_messages(stream, str(file), wanted, declared)
                else:
                    reader = SeekingReader(stream)
                    if declared is not None:
                        _declared_in_summary(reader, declared)
                    messages = reader.iter_messages(topics=wanted)
                try:
                    for schema, channel, message in messages:
                        read[channel.topic] = read.get(channel.topic, 0) + 1
                        yield schema, channel, message
                except _READ_ERRORS as exc:
                    # A damaged record: what came before it is kept, the loss is counted below.
                    _log.warning(
                        '%s: %s is damaged after byte %d (%s); reading stops there',
                        self.path,
                        file.name,
                        stream.tell(),
                        type(exc).__name__,
                    )
        for topic, count in read.items():
            self.check_count(topic, count)

    def check_count(self, topic: str, read: int) -> bool:
        """Warns when fewer messages of a topic were read than the bag's metadata lists.

        A damaged stretch of an MCAP file (overwritten bytes, a bad chunk) makes readers skip
        what it held; the metadata's count is the bag's own record of what it should hold.

        Args:
            topic: The topic read in full.
            read: Messages read.

        Returns:
            Whether every listed message was read (``True`` for a topic the metadata lacks).
        """
        entry = self.topics.get(topic)
        if entry is None or read >= entry.count:
            return True
        _log.warning(
            '%s: %s: read %d of the %d messages that metadata.yaml lists; %d lost to damaged '
            'data (`lumpbeam repair %s` keeps what is readable in a whole bag)',
            self.path,
            topic,
            read,
            entry.count,
            entry.count - read,
            self.path,
        )
        return False

    def messages(self, topic: str, msgtype: str) -> Iterator[tuple[int, Any]]:
        """Iterates over the deserialized messages of one topic.

        Args:
            topic: Topic name.
            msgtype: The type the caller expects.

        Yields:
            ``(log_time_ns, message)``.

        Raises:
            BagError: Missing topic, another type, or a corrupt message.
        """
        self.require(topic, msgtype)
        for raw in self.iter_raw([topic]):
            yield raw.log_time_ns, deserialize(raw.data, raw.msgtype)

    def _probe(self, file: Path) -> object | None:
        """Returns the file's MCAP summary, or ``None`` when it has none (cut recording)."""
        return probe(file, self.path)


def probe(file: Path, bag: Path) -> object | None:
    """Returns an MCAP file's summary, or ``None`` when it has none (a cut recording).

    Args:
        file: The data file.
        bag: Its bag folder, to name in errors.

    Returns:
        The summary, or ``None``.

    Raises:
        BagError: The file is empty, unreadable or not an MCAP file.
    """
    try:
        size = file.stat().st_size
        with file.open('rb') as stream:
            if size == 0:
                raise BagError(f'{bag}: data file {file.name} is empty')
            try:
                reader = SeekingReader(stream)
            except _READ_ERRORS:
                raise BagError(f'{bag}: {file.name} is not an MCAP file') from None
            try:
                return reader.get_summary()
            except (*_READ_ERRORS, OSError):  # OSError: a file shorter than a footer
                return None
    except OSError as exc:
        raise BagError(f'{bag}: cannot read {file.name}: {exc.strerror}') from None


def stream_messages(
    stream: BinaryIO,
    label: str,
    wanted: set[str] | None = None,
    declared: dict[str, tuple[Schema | None, Channel]] | None = None,
) -> Iterator[tuple[Schema | None, Channel, Message]]:
    """Walks an MCAP file from its start, stopping with a warning at an incomplete record.

    Args:
        stream: The open file.
        label: How to name the file in the warning.
        wanted: Topics to yield; all when ``None``.
        declared: Filled, when given, with the schema and channel of every topic the walk
            meets, by topic, whether or not any message of it follows (a declared topic that
            never published is still part of the bag).

    Yields:
        ``(schema, channel, message)`` in file order.
    """
    schemas: dict[int, Schema] = {}
    channels: dict[int, Channel] = {}
    count = 0
    try:
        for record in StreamReader(stream).records:
            if isinstance(record, Schema):
                schemas[record.id] = record
            elif isinstance(record, Channel):
                channels[record.id] = record
                if declared is not None:
                    declared.setdefault(record.topic, (schemas.get(record.schema_id), record))
            elif isinstance(record, Message):
                channel = channels.get(record.channel_id)
                if channel is None or (wanted is not None and channel.topic not in wanted):
                    continue
                count += 1
                yield schemas.get(channel.schema_id), channel, record
    except _READ_ERRORS as exc:
        _log.warning(
            '%s ends in an incomplete record after byte %d (%s); kept %d messages',
            label,
            stream.tell(),
            type(exc).__name__,
            count,
        )


def _declared_in_summary(
    reader: SeekingReader, declared: dict[str, tuple[Schema | None, Channel]]
) -> None:
    """Adds the channels a complete file's summary lists (see :func:`stream_messages`)."""
    summary = reader.get_summary()
    if summary is None:
        return
    for channel in summary.channels.values():
        declared.setdefault(channel.topic, (summary.schemas.get(channel.schema_id), channel))


def _raw(schema: Schema | None, channel: Channel, message: Message) -> RawMessage:
    msgtype = schema.name if schema is not None else channel.message_encoding
    return RawMessage(channel.topic, msgtype, message.log_time, message.data)


def open_bag(bag: str | Path | BagReader) -> BagReader:
    """Returns ``bag`` if it is already open, else opens it."""
    return bag if isinstance(bag, BagReader) else BagReader(bag)
