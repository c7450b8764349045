"""Reading rosbag2 bags with MCAP storage: whole, cut short, or damaged.

The MCAP file is walked record by record from its start, with the ``mcap`` package's record
layout (:mod:`mcap.records`), and every chunk is checked before anything in it is believed:
its declared sizes against the file, its CRC-32 (when its writer stored one, as
:class:`~lumpbeam_ros.bagio.writer.BagWriter` does) against its records. So

- a file whose writer was killed (no closing summary) is read up to its first incomplete
  record, with a warning: everything that reached the disk is read;
- a damaged chunk (overwritten, inserted or missing bytes) is skipped whole and the walk
  goes on after it; where the damage broke the record framing, the walk resumes at the next
  chunk the file's (CRC-checked) summary lists, or else at the next place that holds an
  intact chunk;
- what was lost is counted per topic against ``metadata.yaml`` (the bag's own record of
  what it holds) and reported as one warning line naming the bag, the topic and the count
  (:meth:`BagReader.report_loss`); a message that does not decode is skipped and counted the
  same way (:meth:`BagReader.messages`). Nothing in a damaged file raises anything but
  :class:`~lumpbeam_ros.errors.BagError`, and the work is bounded by the file's size.
"""

from __future__ import annotations

import logging
import mmap
import struct
import zlib
from collections import Counter
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import zstandard
from mcap.exceptions import McapError
from mcap.reader import SeekingReader
from mcap.records import Channel, Message, Schema
from mcap.summary import Summary

from lumpbeam_ros.bagio import metadata
from lumpbeam_ros.bagio.typestore import deserialize
from lumpbeam_ros.errors import BagError

_log = logging.getLogger(__name__)

MAGIC = b'\x89MCAP0\r\n'
_OP_FOOTER, _OP_SCHEMA, _OP_CHANNEL, _OP_MESSAGE, _OP_CHUNK = 0x02, 0x03, 0x04, 0x05, 0x06
_OP_DATA_END = 0x0F
#: The opcodes of MCAP version 0; anything else where a record should start is damage.
_KNOWN_OPCODES = frozenset(range(0x01, 0x10))
_RECORD = struct.Struct('<BQ')
_CHUNK_HEAD = struct.Struct('<QQQI')  # message start and end time, uncompressed size and CRC
_MESSAGE_HEAD = struct.Struct('<HIQQ')  # channel, sequence, log time, publish time
_FOOTER = struct.Struct('<BQQQI')  # opcode, length, summary start, summary offset start, CRC
_U16, _U32, _U64 = struct.Struct('<H'), struct.Struct('<I'), struct.Struct('<Q')
#: Largest chunk decompressed (a damaged size field must not become a huge allocation).
MAX_CHUNK_BYTES = 1 << 30

# What the mcap package and the decompressors raise on malformed bytes.
_READ_ERRORS = (
    McapError,
    struct.error,
    EOFError,
    ValueError,
    IndexError,
    KeyError,
    UnicodeDecodeError,
    OverflowError,
    MemoryError,
    RuntimeError,
    zstandard.ZstdError,
)


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
        lost: Messages lost per topic (unreadable or undecodable) in the last complete read
            of that topic; a topic read without a loss is absent.
    """

    def __init__(self, path: str | Path):
        self.path = Path(path)
        self.info = metadata.load(self.path)
        self.truncated: list[Path] = []
        self.lost: dict[str, int] = {}
        self._summaries: dict[Path, Summary | None] = {}
        for file in self.info.files:
            summary = probe(file, self.path)
            self._summaries[file] = summary
            if summary is None:
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

    def iter_raw(
        self, topics: Iterable[str] | None = None, *, report: bool = True
    ) -> Iterator[RawMessage]:
        """Iterates over the serialized messages whose chunks are intact, in file order.

        The product's files are in log-time order (:class:`~.writer.BagWriter` sorts them);
        in a complete file each chunk's messages come sorted by log time (:class:`FileWalk`).

        Args:
            topics: Topics to read; all when ``None``.
            report: Warn at the end of a complete pass about what was lost, per topic
                (:meth:`report_loss`); ``False`` leaves that to the caller.

        Yields:
            The messages.
        """
        for schema, channel, message in self.iter_records(topics, report=report):
            yield _raw(schema, channel, message)

    def iter_records(
        self,
        topics: Iterable[str] | None = None,
        declared: dict[str, tuple[Schema | None, Channel]] | None = None,
        *,
        report: bool = True,
    ) -> Iterator[tuple[Schema | None, Channel, Message]]:
        """Iterates over the MCAP records of the messages, with their schema and channel.

        What :meth:`iter_raw` reads, with what a copy of the bag needs besides (the schema's
        message definition, the channel's metadata).

        Args:
            topics: Topics to read; all when ``None``.
            declared: Filled, when given, with the schema and channel of every topic the data
                files declare, messages or not.
            report: As in :meth:`iter_raw`.

        Yields:
            ``(schema, channel, message)``, in file order.
        """
        wanted = None if topics is None else set(topics)
        read: Counter[str] = Counter(dict.fromkeys(self.topics if wanted is None else wanted, 0))
        self.last_read = read
        for file in self.info.files:
            walk = FileWalk(file, self.path, self._summaries.get(file), wanted, declared)
            for schema, channel, message in walk:
                read[channel.topic] += 1
                yield schema, channel, message
        if report:
            for topic, count in read.items():
                self.report_loss(topic, count)

    def report_loss(self, topic: str, read: int, undecodable: int = 0, error: str = '') -> int:
        """Counts what a complete read of a topic lost, and warns about it in one line.

        A damaged stretch of an MCAP file (overwritten bytes, a bad chunk) makes the reader
        skip what it held; the metadata's count is the bag's own record of what it should
        hold. A message that was read but does not decode is lost too.

        Args:
            topic: The topic read in full.
            read: Messages read (decodable or not).
            undecodable: Of those, the messages that did not decode.
            error: The first decoding error, to quote.

        Returns:
            The messages lost (also kept in :attr:`lost`).
        """
        entry = self.topics.get(topic)
        missing = max(0, entry.count - read) if entry is not None else 0
        lost = missing + undecodable
        self.lost.pop(topic, None)
        if not lost:
            return 0
        self.lost[topic] = lost
        listed = entry.count if entry is not None else read
        parts = []
        if missing:
            parts.append(f'{missing} in damaged data')
        if undecodable:
            parts.append(f'{undecodable} undecodable: {error}')
        _log.warning(
            '%s: %s: lost %d of the %d messages that metadata.yaml lists (%s); '
            '`lumpbeam repair %s` keeps what is readable in a whole bag',
            self.path,
            topic,
            lost,
            listed,
            '; '.join(parts),
            self.path,
        )
        return lost

    def check_count(self, topic: str, read: int) -> bool:
        """Warns when fewer messages of a topic were read than the bag's metadata lists.

        Args:
            topic: The topic read in full.
            read: Messages read.

        Returns:
            Whether every listed message was read (``True`` for a topic the metadata lacks).
        """
        return self.report_loss(topic, read) == 0

    def messages(self, topic: str, msgtype: str) -> Iterator[tuple[int, Any]]:
        """Iterates over the deserialized messages of one topic, skipping undecodable ones.

        A message that does not decode is counted, and reported with what the damaged data
        lost, in one warning line once the topic has been read (:meth:`report_loss`).

        Args:
            topic: Topic name.
            msgtype: The type the caller expects.

        Yields:
            ``(log_time_ns, message)``.

        Raises:
            BagError: Missing topic, another type, or a type the typestore does not know.
        """
        self.require(topic, msgtype)
        read = undecodable = 0
        first_error = ''
        for raw in self.iter_raw([topic], report=False):
            read += 1
            try:
                message = deserialize(raw.data, raw.msgtype)
            except BagError as exc:
                if 'unknown message type' in str(exc):
                    raise
                undecodable += 1
                first_error = first_error or str(exc)
                continue
            yield raw.log_time_ns, message
        self.report_loss(topic, read, undecodable, first_error)


def probe(file: Path, bag: Path) -> Summary | None:
    """Returns an MCAP file's summary, or ``None`` when it has no usable one.

    A file without a summary is a cut recording; a summary whose CRC does not match, or that
    does not parse, is damaged: neither is trusted.

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
            if stream.read(len(MAGIC)) != MAGIC:
                raise BagError(f'{bag}: {file.name} is not an MCAP file')
            if not _summary_crc_ok(stream, size):
                return None
            stream.seek(0)
            try:
                return SeekingReader(stream).get_summary()
            except (*_READ_ERRORS, OSError):  # OSError: a seek before the start
                return None
    except OSError as exc:
        raise BagError(f'{bag}: cannot read {file.name}: {exc.strerror}') from None


def _summary_crc_ok(stream: Any, size: int) -> bool:
    """Tells whether the file ends in a footer whose summary CRC (if any) matches."""
    if size < len(MAGIC) * 2 + _FOOTER.size:
        return False
    stream.seek(size - len(MAGIC) - _FOOTER.size)
    tail = stream.read(_FOOTER.size + len(MAGIC))
    if tail[-len(MAGIC) :] != MAGIC:
        return False
    opcode, length, summary_start, _, crc = _FOOTER.unpack_from(tail)
    if opcode != _OP_FOOTER or length != _FOOTER.size - _RECORD.size:
        return False
    footer_at = size - len(MAGIC) - _FOOTER.size
    if crc == 0:
        return bool(summary_start <= footer_at)
    if not len(MAGIC) <= summary_start <= footer_at:
        return False
    stream.seek(summary_start)
    covered = stream.read(footer_at + _FOOTER.size - 4 - summary_start)
    return bool(zlib.crc32(covered) == crc)


class FileWalk:
    """One pass over an MCAP file's data section that skips what is damaged.

    Iterating yields ``(schema, channel, message)`` for every message of the wanted topics
    found in an intact chunk (or outside chunks), in file order; with a summary, each chunk's
    messages in log-time order (chunks themselves stay in file order, which is log-time
    order for every writer that closes a chunk before it starts the next).

    Args:
        file: The ``.mcap`` file.
        bag: Its bag folder, to name in warnings.
        summary: The file's CRC-checked summary (``None``: cut or damaged): its schemas and
            channels define topics whose own records were lost, its chunk indexes are where
            the walk resumes after damage.
        wanted: Topics to yield; all when ``None``.
        declared: Filled, when given, with the schema and channel of every topic the file
            declares (in its summary or its records), whether or not a message follows.

    Attributes:
        damaged: One line per damaged stretch skipped.
        cut: Whether the file ends in an incomplete record (a cut recording).
        sort_chunks: Whether each chunk's messages are sorted by log time (a summary was
            given: the file is complete).
    """

    def __init__(
        self,
        file: Path,
        bag: Path,
        summary: Summary | None = None,
        wanted: set[str] | None = None,
        declared: dict[str, tuple[Schema | None, Channel]] | None = None,
    ):
        self.file = file
        self.bag = bag
        self.wanted = wanted
        self.declared = declared
        self.schemas: dict[int, Schema] = {}
        self.channels: dict[int, Channel] = {}
        self.chunk_starts: list[int] = []
        self.damaged: list[str] = []
        self.cut = False
        self.messages = 0
        self.sort_chunks = summary is not None
        if summary is not None:
            for schema in summary.schemas.values():
                self.schemas[schema.id] = schema
            for channel in summary.channels.values():
                self._define_channel(channel)
            self.chunk_starts = sorted(i.chunk_start_offset for i in summary.chunk_indexes)

    def __iter__(self) -> Iterator[tuple[Schema | None, Channel, Message]]:
        try:
            with self.file.open('rb') as stream:
                if self.file.stat().st_size <= len(MAGIC):
                    self._note_cut(len(MAGIC))
                    return
                with mmap.mmap(stream.fileno(), 0, access=mmap.ACCESS_READ) as buffer:
                    yield from self._walk(buffer)
        except OSError as exc:
            raise BagError(f'{self.bag}: cannot read {self.file.name}: {exc.strerror}') from None
        if self.damaged:
            # Where, for whoever debugs; what it cost is the reader's warning, per topic.
            shown = '; '.join(self.damaged[:3])
            more = f' and {len(self.damaged) - 3} more' if len(self.damaged) > 3 else ''
            _log.info('%s: %s is damaged: skipped %s%s', self.bag, self.file.name, shown, more)

    # -- the walk ---------------------------------------------------------------------------

    def _walk(self, buffer: mmap.mmap) -> Iterator[tuple[Schema | None, Channel, Message]]:
        size = len(buffer)
        offset = len(MAGIC)
        chunked = bool(self.chunk_starts)
        while offset < size:
            if size - offset < _RECORD.size:
                self._note_cut(offset)
                return
            opcode, length = _RECORD.unpack_from(buffer, offset)
            body = offset + _RECORD.size
            end = body + length
            framed = opcode in _KNOWN_OPCODES and end <= size
            records = None
            if framed and opcode == _OP_CHUNK:
                chunked = True
                records = self._chunk_records(buffer, offset, body, end)
                framed = records is not None
            if not framed:
                resume = self._next_chunk(buffer, offset + 1)
                if resume is None and end > size and not self.damaged:
                    self._note_cut(offset)  # a record cut by the end of the file
                    return
                what = 'a damaged chunk' if opcode == _OP_CHUNK else 'unreadable records'
                offset = self._skip(offset, resume, size, what)
                continue
            if records is not None:
                chunk = self._records(records, offset)
                if self.sort_chunks:
                    # As mcap's own reader does with a summary: a chunk's messages in log
                    # time, so that a file written out of order (rosbags' writer keeps the
                    # order it is given) replays with a clock that never turns back.
                    chunk = iter(sorted(chunk, key=lambda record: record[2].log_time))
                yield from chunk
            elif opcode in (_OP_DATA_END, _OP_FOOTER):
                return
            elif not chunked and not self.damaged:
                # Records outside chunks are only believed in an unchunked file read without
                # damage so far: after damage, garbage may look like one.
                if opcode == _OP_MESSAGE:
                    yield from self._message(buffer, body, end)
                elif opcode in (_OP_SCHEMA, _OP_CHANNEL):
                    self._definition(opcode, buffer, body, end)
            offset = end

    def _skip(self, offset: int, resume: int | None, size: int, what: str) -> int:
        """Notes a damaged stretch from ``offset`` to where the walk resumes."""
        stop = size if resume is None else resume
        self.damaged.append(f'{what} at bytes {offset}-{stop}')
        return stop

    def _note_cut(self, offset: int) -> None:
        self.cut = True
        _log.warning(
            '%s: %s ends in an incomplete record after byte %d; kept %d messages',
            self.bag,
            self.file.name,
            offset,
            self.messages,
        )

    def _next_chunk(self, buffer: mmap.mmap, start: int) -> int | None:
        """Where the next intact chunk after ``start`` begins (``None``: there is none).

        The summary's chunk indexes say it when the file has a trustworthy summary; else the
        bytes are searched for a chunk record whose sizes fit and whose CRC matches.
        """
        if self.chunk_starts:
            return next((at for at in self.chunk_starts if at >= start), None)
        at = buffer.find(bytes([_OP_CHUNK]), start)
        while at != -1:
            if self._plausible_chunk(buffer, at):
                return at
            at = buffer.find(bytes([_OP_CHUNK]), at + 1)
        return None

    def _plausible_chunk(self, buffer: mmap.mmap, at: int) -> bool:
        try:
            _, length = _RECORD.unpack_from(buffer, at)
            body = at + _RECORD.size
            end = body + length
            if end > len(buffer) or length < _CHUNK_HEAD.size + 12:
                return False
            return self._chunk_data(buffer, body, end, quiet=True) is not None
        except _READ_ERRORS:
            return False

    # -- chunks -----------------------------------------------------------------------------

    def _chunk_records(self, buffer: mmap.mmap, offset: int, body: int, end: int) -> Any:
        """The records of an intact chunk; ``None`` for a damaged one."""
        try:
            records = self._chunk_data(buffer, body, end)
        except _READ_ERRORS as exc:
            records = f'{type(exc).__name__}'
        return None if isinstance(records, str) else records

    def _chunk_data(self, buffer: mmap.mmap, body: int, end: int, quiet: bool = False) -> Any:
        """Decompresses and checks a chunk; a string says what is wrong with it."""
        _, _, size, crc = _CHUNK_HEAD.unpack_from(buffer, body)
        at = body + _CHUNK_HEAD.size
        (name_length,) = _U32.unpack_from(buffer, at)
        if name_length > 8:
            return None if quiet else f'compression name of {name_length} bytes'
        compression = bytes(buffer[at + 4 : at + 4 + name_length]).decode('ascii')
        at += 4 + name_length
        (length,) = _U64.unpack_from(buffer, at)
        at += 8
        if at + length != end or size > MAX_CHUNK_BYTES:
            return None if quiet else 'sizes do not fit the record'
        data = memoryview(buffer)[at:end]
        try:
            if compression == '':
                records: bytes | memoryview = data
            elif compression == 'zstd':
                if zstandard.frame_content_size(data) != size:
                    return None if quiet else 'compressed size does not match'
                records = zstandard.ZstdDecompressor().decompress(data, max_output_size=size)
            elif compression == 'lz4':
                import lz4.frame

                records = lz4.frame.decompress(bytes(data))
            else:
                return None if quiet else f'unknown compression {compression!r}'
            if len(records) != size:
                return None if quiet else 'uncompressed size does not match'
            if crc and zlib.crc32(records) != crc:
                return None if quiet else 'CRC mismatch'
            return bytes(records)
        finally:
            data.release()

    def _records(
        self, records: bytes, offset: int
    ) -> Iterator[tuple[Schema | None, Channel, Message]]:
        """The messages of a chunk's records (a record that does not parse ends the chunk)."""
        at, size = 0, len(records)
        while at < size:
            try:
                opcode, length = _RECORD.unpack_from(records, at)
            except struct.error:
                opcode, length = 0, size
            body = at + _RECORD.size
            end = body + length
            if end > size:
                self.damaged.append(f'the rest of the chunk at byte {offset} (a cut record)')
                return
            if opcode == _OP_MESSAGE:
                yield from self._message(records, body, end)
            elif opcode in (_OP_SCHEMA, _OP_CHANNEL):
                self._definition(opcode, records, body, end)
            at = end

    # -- records ----------------------------------------------------------------------------

    def _message(
        self, buffer: Any, body: int, end: int
    ) -> Iterator[tuple[Schema | None, Channel, Message]]:
        if end - body < _MESSAGE_HEAD.size:
            self.damaged.append('a message record too short for its header')
            return
        channel_id, sequence, log_time, publish_time = _MESSAGE_HEAD.unpack_from(buffer, body)
        channel = self.channels.get(channel_id)
        if channel is None or (self.wanted is not None and channel.topic not in self.wanted):
            return  # a message of a channel whose definition was lost is counted as lost
        data = bytes(buffer[body + _MESSAGE_HEAD.size : end])
        self.messages += 1
        yield (
            self.schemas.get(channel.schema_id),
            channel,
            Message(
                channel_id=channel_id,
                log_time=log_time,
                data=data,
                publish_time=publish_time,
                sequence=sequence,
            ),
        )

    def _definition(self, opcode: int, buffer: Any, body: int, end: int) -> None:
        try:
            content = _Cursor(bytes(buffer[body:end]))
            if opcode == _OP_SCHEMA:
                schema_id, name, encoding = content.u16(), content.string(), content.string()
                schema = Schema(id=schema_id, data=content.bytes(), encoding=encoding, name=name)
                self.schemas.setdefault(schema.id, schema)
            else:
                channel_id, schema_id = content.u16(), content.u16()
                topic, encoding = content.string(), content.string()
                channel = Channel(
                    id=channel_id,
                    topic=topic,
                    message_encoding=encoding,
                    metadata=content.string_map(),
                    schema_id=schema_id,
                )
                self._define_channel(channel)
        except _READ_ERRORS:
            self.damaged.append('a schema or channel record that does not parse')

    def _define_channel(self, channel: Channel) -> None:
        self.channels.setdefault(channel.id, channel)
        if self.declared is not None:
            self.declared.setdefault(
                channel.topic, (self.schemas.get(channel.schema_id), self.channels[channel.id])
            )


class _Cursor:
    """Reads MCAP's little-endian fields from a record's content, failing on a short read."""

    def __init__(self, data: bytes):
        self.data = data
        self.at = 0

    def _take(self, n: int) -> bytes:
        if n > len(self.data) - self.at:
            raise ValueError('field runs past its record')
        chunk = self.data[self.at : self.at + n]
        self.at += n
        return chunk

    def u16(self) -> int:
        return int(_U16.unpack(self._take(2))[0])

    def bytes(self) -> bytes:
        return self._take(int(_U32.unpack(self._take(4))[0]))

    def string(self) -> str:
        return self.bytes().decode()

    def string_map(self) -> dict[str, str]:
        end = int(_U32.unpack(self._take(4))[0]) + self.at
        if end > len(self.data):
            raise ValueError('map runs past its record')
        pairs = {}
        while self.at < end:
            key = self.string()
            pairs[key] = self.string()
        return pairs


def _raw(schema: Schema | None, channel: Channel, message: Message) -> RawMessage:
    msgtype = schema.name if schema is not None else channel.message_encoding
    return RawMessage(channel.topic, msgtype, message.log_time, message.data)


def open_bag(bag: str | Path | BagReader) -> BagReader:
    """Returns ``bag`` if it is already open, else opens it."""
    return bag if isinstance(bag, BagReader) else BagReader(bag)
