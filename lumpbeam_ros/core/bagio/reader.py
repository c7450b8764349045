"""Reading rosbag2 bags with MCAP storage: whole, cut short, or damaged.

The ``mcap`` package reads the records: each record's content is parsed by mcap's reader of
its kind (:func:`read_record_at`, the one record reader, which the structural check of
:mod:`~lumpbeam_ros.core.bagio.check` uses too), a chunk is decompressed by mcap
(:func:`decompress_chunk`) and checked against its CRC-32 (when its writer stored one, as
:class:`~lumpbeam_ros.core.bagio.writer.BagWriter` does), and
:class:`mcap.reader.SeekingReader` reads the closing summary. What this module adds is the
policy for damage, which the package's own ``iter_messages`` does not have (it stops the
whole read at the first bad chunk):

- a complete file is read chunk by chunk through its summary's chunk indexes (the summary
  first checked against its CRC); a chunk that does not read, does not match its index or
  fails its CRC is skipped whole, and the next chunk is read as if nothing happened;
- a file without a usable summary (a recording whose writer was killed, or a damaged
  summary) is read as a stream of records, up to its first incomplete record (with a
  warning: everything that reached the disk is read); where a record does not parse, the
  stream resumes at the next place that holds an intact chunk;
- what was lost is counted per topic against ``metadata.yaml`` (the bag's own record of
  what it holds) and reported as one warning line naming the bag, the topic and the count
  (:meth:`BagReader.report_loss`); a message that does not decode is skipped and counted the
  same way (:meth:`BagReader.messages`). Nothing in a damaged file raises anything but
  :class:`~lumpbeam_ros.base.errors.BagError`, and the work is bounded by the file's size.
"""

from __future__ import annotations

import io
import logging
import mmap
import struct
import zlib
from collections import Counter
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any, cast

import zstandard
from mcap.data_stream import ReadDataStream
from mcap.exceptions import EndOfFile, McapError
from mcap.opcode import Opcode
from mcap.reader import FOOTER_SIZE, SeekingReader
from mcap.records import (
    Attachment,
    AttachmentIndex,
    Channel,
    Chunk,
    ChunkIndex,
    DataEnd,
    Footer,
    Header,
    McapRecord,
    Message,
    MessageIndex,
    Metadata,
    MetadataIndex,
    Schema,
    Statistics,
    SummaryOffset,
)
from mcap.stream_reader import StreamReader, get_chunk_data_stream, read_magic
from mcap.summary import Summary
from mcap.writer import MCAP0_MAGIC

from lumpbeam_ros.base.errors import BagError
from lumpbeam_ros.core.bagio import metadata
from lumpbeam_ros.core.bagio.fastscan import message_record
from lumpbeam_ros.core.bagio.typestore import deserialize

_log = logging.getLogger(__name__)

#: The bytes an MCAP file starts and ends with.
MAGIC = MCAP0_MAGIC
#: Largest chunk decompressed (a damaged size field must not become a huge allocation).
MAX_CHUNK_BYTES = 1 << 30
#: A record's opcode and length, before its content.
_RECORD_PREFIX = 1 + 8
#: A chunk's fields besides its compression's name and its data: start and end times, the
#: uncompressed size and CRC, the lengths of the name and of the data.
_CHUNK_FIELDS = 8 + 8 + 8 + 4 + 4 + 8
#: The compressions of MCAP chunks ('': none).
_COMPRESSIONS = ('', 'zstd', 'lz4')

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

    def schemas(self) -> dict[str, Schema]:
        """The schema of each topic's channel, as the data files' summaries declare them.

        A file without a usable summary (cut, damaged) adds none: it is read without them.
        """
        found: dict[str, Schema] = {}
        for summary in self._summaries.values():
            if summary is None:
                continue
            for channel in summary.channels.values():
                schema = summary.schemas.get(channel.schema_id)
                if schema is not None:
                    found[channel.topic] = schema
        return found

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
        with file.open('rb') as stream:
            if file.stat().st_size == 0:
                raise BagError(f'{bag}: data file {file.name} is empty')
            with mmap.mmap(stream.fileno(), 0, access=mmap.ACCESS_READ) as buffer:
                return _summary(buffer, f'{bag}: {file.name}')
    except OSError as exc:
        raise BagError(f'{bag}: cannot read {file.name}: {exc.strerror}') from None


def _summary(buffer: mmap.mmap, name: str) -> Summary | None:
    stream = _as_stream(buffer)
    try:
        read_magic(ReadDataStream(stream))
    except (McapError, struct.error):
        raise BagError(f'{name} is not an MCAP file') from None
    try:
        if not _summary_crc_ok(buffer):
            return None
        buffer.seek(0)
        return SeekingReader(stream, record_size_limit=len(buffer)).get_summary()
    except (*_READ_ERRORS, OSError):  # OSError: a seek before the start
        return None


def _summary_crc_ok(buffer: mmap.mmap) -> bool:
    """Tells whether the file ends in a footer whose summary CRC (if it has one) matches.

    mcap's reader takes a summary as it finds it; a damaged one must not direct the walk.
    """
    size = len(buffer)
    footer_at = size - len(MAGIC) - FOOTER_SIZE
    if footer_at < len(MAGIC):
        return False
    buffer.seek(footer_at)
    # The reader stops after the footer and the closing magic, which it checks.
    reader = StreamReader(_as_stream(buffer), skip_magic=True, record_size_limit=FOOTER_SIZE)
    records = list(reader.records)
    if len(records) != 1 or not isinstance(records[0], Footer) or buffer.tell() != size:
        return False
    footer = records[0]
    if footer.summary_crc == 0:
        return bool(footer.summary_start <= footer_at)
    if not len(MAGIC) <= footer.summary_start <= footer_at:
        return False
    # The CRC covers the summary and the footer up to the CRC field itself.
    covered = buffer[footer.summary_start : footer_at + FOOTER_SIZE - 4]
    return bool(zlib.crc32(covered) == footer.summary_crc)


class UnreadableRecordError(Exception):
    """No record can be read where one should start.

    Attributes:
        cut: Whether the data end inside it (its header, or the content its length declares).
    """

    def __init__(self, reason: str, cut: bool):
        super().__init__(reason)
        self.cut = cut


#: mcap's readers of each record's content, by opcode.
_RECORD_READERS: dict[int, Callable[[ReadDataStream], McapRecord]] = {
    Opcode.ATTACHMENT: Attachment.read,
    Opcode.ATTACHMENT_INDEX: AttachmentIndex.read,
    Opcode.CHANNEL: Channel.read,
    Opcode.CHUNK: Chunk.read,
    Opcode.CHUNK_INDEX: ChunkIndex.read,
    Opcode.DATA_END: DataEnd.read,
    Opcode.FOOTER: Footer.read,
    Opcode.HEADER: Header.read,
    Opcode.MESSAGE_INDEX: MessageIndex.read,
    Opcode.METADATA: Metadata.read,
    Opcode.METADATA_INDEX: MetadataIndex.read,
    Opcode.SCHEMA: Schema.read,
    Opcode.STATISTICS: Statistics.read,
    Opcode.SUMMARY_OFFSET: SummaryOffset.read,
}


class _ExactStream(ReadDataStream):
    """A :class:`ReadDataStream` that fails on a short read instead of returning less."""

    def read(self, length: int) -> bytes:
        data = super().read(length)
        if len(data) != length:
            raise EndOfFile()
        return data


def opcode_name(opcode: int) -> str:
    """A record's kind as the MCAP specification names it (``'ChunkIndex'``)."""
    try:
        return Opcode(opcode).name.title().replace('_', '')
    except ValueError:
        return f'opcode 0x{opcode:02x}'


def read_record_at(
    data: bytes | mmap.mmap, at: int, end: int, where: str, inside: str = ''
) -> tuple[int, McapRecord | None, int]:
    """The record that starts at ``at``: the one record reader of the walks over MCAP bytes.

    The file walk of a cut or damaged file, a chunk's records and the structural check
    (:mod:`~lumpbeam_ros.core.bagio.check`) all read records here: the opcode and length,
    then the content by mcap's reader of that kind of record, bounded by its length.

    Args:
        data: The bytes (a file's map, or a chunk's records).
        at: Where the record starts.
        end: Where the data end.
        where: The record's place, for the reason (``'offset 8'``).
        inside: Said after the bytes left when the record runs past ``end``.

    Returns:
        The opcode, the record (``None``: an opcode mcap does not know, skipped as the
        specification says) and where the record ends.

    Raises:
        UnreadableRecordError: Its header is cut, it declares more bytes than are left, or its
            content does not parse.
    """
    if end - at < _RECORD_PREFIX:
        raise UnreadableRecordError(f'a record header at {where} is cut', cut=True)
    prefix = ReadDataStream(io.BytesIO(data[at : at + _RECORD_PREFIX]))
    opcode, length = prefix.read1(), prefix.read8()
    left = end - at - _RECORD_PREFIX
    if length > left:
        raise UnreadableRecordError(
            f'{opcode_name(opcode)} record at {where} declares {length} bytes, only {left} '
            f'are left{inside}',
            cut=True,
        )
    start, stop = at + _RECORD_PREFIX, at + _RECORD_PREFIX + length
    if opcode == Opcode.MESSAGE:
        # Nearly every record of a bag, an image's megabyte among them.
        message = message_record(data, start, stop)
        if message is not None:
            return opcode, message, stop
    body = bytes(data[start:stop])
    stream = _ExactStream(io.BytesIO(body))
    try:
        if opcode == Opcode.MESSAGE:
            record: McapRecord | None = Message.read(stream, len(body))
        else:
            reader = _RECORD_READERS.get(opcode)
            record = None if reader is None else reader(stream)
    except _READ_ERRORS as exc:
        detail = f': {exc}' if str(exc) else ''
        raise UnreadableRecordError(
            f'{opcode_name(opcode)} record at {where} does not parse '
            f'({type(exc).__name__}{detail})',
            cut=False,
        ) from None
    return opcode, record, at + _RECORD_PREFIX + length


def decompress_chunk(chunk: Chunk) -> bytes:
    """A chunk's records as written, decompressed by mcap (not checked against its CRC).

    Raises:
        UnreadableRecordError: An unknown compression, a size no chunk should have, or data the
            decompressor refuses (the reason names the error).
    """
    if chunk.compression not in _COMPRESSIONS:
        # mcap takes an unknown compression for none.
        raise UnreadableRecordError(f'UnsupportedCompression: {chunk.compression!r}', cut=False)
    if chunk.uncompressed_size > MAX_CHUNK_BYTES:
        raise UnreadableRecordError(
            f'ValueError: uncompressed_size {chunk.uncompressed_size} is over '
            f'{MAX_CHUNK_BYTES} bytes',
            cut=False,
        )
    try:
        if chunk.compression == 'zstd':
            # The decompressor allocates the size the frame states, not the record's.
            stated = zstandard.frame_content_size(chunk.data)
            if stated != chunk.uncompressed_size:
                raise ValueError(f'the zstd frame states {stated} bytes')
        stream, size = get_chunk_data_stream(chunk, validate_crc=False)
        return bytes(stream.read(size))
    except _READ_ERRORS as exc:
        raise UnreadableRecordError(f'{type(exc).__name__}: {exc}', cut=False) from None


def _as_stream(buffer: mmap.mmap) -> IO[bytes]:
    """The file's map as the stream mcap reads from.

    A map's ``read(n)`` returns what is there: a damaged length field asks for gigabytes,
    which a file object would allocate before reading.
    """
    return cast(IO[bytes], buffer)


def _read_record(buffer: mmap.mmap, at: int) -> tuple[McapRecord, int] | None:
    """The record at ``at`` as mcap parses it, and where it ends (``None``: none readable).

    A chunk comes whole (:class:`~mcap.records.Chunk`, not yet decompressed).
    """
    try:
        _, record, end = read_record_at(buffer, at, len(buffer), f'offset {at}')
    except UnreadableRecordError:
        return None
    return None if record is None else (record, end)


def _chunk_end(at: int, chunk: Chunk) -> int:
    """Where a chunk record that starts at ``at`` ends, by the fields mcap read from it.

    mcap skips to the end its length field declares; one that disagrees with the content
    would make a stream skip (or reread) the records after it.
    """
    content = _CHUNK_FIELDS + len(chunk.compression.encode()) + len(chunk.data)
    return at + _RECORD_PREFIX + content


def _chunk_records(chunk: Chunk) -> list[McapRecord] | None:
    """A chunk's records, decompressed, CRC-checked and parsed by mcap (``None``: damaged)."""
    try:
        data = decompress_chunk(chunk)
    except UnreadableRecordError:
        return None
    if len(data) != chunk.uncompressed_size:
        return None
    if chunk.uncompressed_crc != 0 and zlib.crc32(data) != chunk.uncompressed_crc:
        return None
    records = []
    at = 0
    while at < len(data):
        try:
            _, record, at = read_record_at(data, at, len(data), 'a chunk')
        except UnreadableRecordError:
            return None
        if record is not None:
            records.append(record)
    return records


class FileWalk:
    """One pass over an MCAP file's messages that skips what is damaged.

    Iterating yields ``(schema, channel, message)`` for every message of the wanted topics
    found in an intact chunk (or outside chunks), in file order. With a summary, the chunks
    its indexes list are read one by one, each chunk's messages in log-time order (chunks
    themselves stay in file order, which is log-time order for every writer that closes a
    chunk before it starts the next). Without one, the records are read as a stream.

    Args:
        file: The ``.mcap`` file.
        bag: Its bag folder, to name in warnings.
        summary: The file's CRC-checked summary (``None``: cut or damaged): its schemas and
            channels define topics whose own records were lost, its chunk indexes are the
            chunks to read.
        wanted: Topics to yield; all when ``None``.
        declared: Filled, when given, with the schema and channel of every topic the file
            declares (in its summary or its records), whether or not a message follows.

    Attributes:
        damaged: One line per damaged stretch skipped.
        cut: Whether the file ends in an incomplete record (a cut recording).
        messages: Messages yielded so far.
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
        self.chunk_indexes: list[ChunkIndex] = []
        self.damaged: list[str] = []
        self.cut = False
        self.messages = 0
        if summary is not None:
            for schema in summary.schemas.values():
                self.schemas[schema.id] = schema
            for channel in summary.channels.values():
                self._define_channel(channel)
            self.chunk_indexes = sorted(summary.chunk_indexes, key=lambda i: i.chunk_start_offset)

    def __iter__(self) -> Iterator[tuple[Schema | None, Channel, Message]]:
        try:
            with self.file.open('rb') as stream:
                if self.file.stat().st_size <= len(MAGIC):
                    self._note_cut(len(MAGIC))
                    return
                with mmap.mmap(stream.fileno(), 0, access=mmap.ACCESS_READ) as buffer:
                    if self.chunk_indexes:
                        yield from self._indexed(buffer)
                    else:
                        yield from self._streamed(buffer)
        except OSError as exc:
            raise BagError(f'{self.bag}: cannot read {self.file.name}: {exc.strerror}') from None
        if self.damaged:
            # Where, for whoever debugs; what it cost is the reader's warning, per topic.
            shown = '; '.join(self.damaged[:3])
            more = f' and {len(self.damaged) - 3} more' if len(self.damaged) > 3 else ''
            _log.info('%s: %s is damaged: skipped %s%s', self.bag, self.file.name, shown, more)

    # -- a complete file: chunk by chunk, through the summary -------------------------------

    def _indexed(self, buffer: mmap.mmap) -> Iterator[tuple[Schema | None, Channel, Message]]:
        wanted = self._wanted_channels()
        for index in self.chunk_indexes:
            if wanted is not None and index.message_index_offsets:
                if wanted.isdisjoint(index.message_index_offsets):
                    # Its message index (in the CRC-checked summary) lists none of the
                    # wanted channels: a topic of a few messages, as /tip_load, is read
                    # from its own chunks, not from every chunk of the poses beside it.
                    continue
            records = self._indexed_chunk(buffer, index)
            if records is None:
                start = index.chunk_start_offset
                self.damaged.append(
                    f'a damaged chunk at bytes {start}-{start + index.chunk_length}'
                )
                continue
            # As mcap's own reader does with a summary: a chunk's messages in log time, so
            # that a file written out of order (rosbags' writer keeps the order it is given)
            # replays with a clock that never turns back.
            chunk = list(self._records(records))
            chunk.sort(key=lambda record: record[2].log_time)
            yield from chunk

    def _wanted_channels(self) -> set[int] | None:
        """The summary's channel ids of the wanted topics (``None``: every topic is wanted)."""
        if self.wanted is None:
            return None
        return {id_ for id_, channel in self.channels.items() if channel.topic in self.wanted}

    @staticmethod
    def _indexed_chunk(buffer: mmap.mmap, index: ChunkIndex) -> list[McapRecord] | None:
        """The records of the chunk an index points at, if it is the chunk the index lists."""
        start = index.chunk_start_offset
        read = _read_record(buffer, start) if len(MAGIC) <= start < len(buffer) else None
        if read is None:
            return None
        chunk, end = read
        if (
            not isinstance(chunk, Chunk)
            or end != start + index.chunk_length
            or chunk.compression != index.compression
            or len(chunk.data) != index.compressed_size
            or chunk.uncompressed_size != index.uncompressed_size
        ):
            return None
        return _chunk_records(chunk)

    # -- a cut or damaged file: record by record --------------------------------------------

    def _streamed(self, buffer: mmap.mmap) -> Iterator[tuple[Schema | None, Channel, Message]]:
        size = len(buffer)
        at = len(MAGIC)
        chunked = False
        while at < size:
            try:
                _, record, end = read_record_at(buffer, at, size, f'offset {at}')
            except UnreadableRecordError as exc:
                # A record that runs past the end of the file: cut, unless data follows.
                resume = self._resume(buffer, at, exc.cut)
                if resume is None:
                    return
                at = resume
                continue
            if isinstance(record, Chunk):
                chunked = True
                intact = end == _chunk_end(at, record)
                records = _chunk_records(record) if intact else None
                if records is None:
                    resume = self._resume(buffer, at, cut=False)
                    if resume is None:
                        return
                    at = resume
                    continue
                yield from self._records(records)
            elif isinstance(record, DataEnd | Footer):
                return
            elif record is not None and not chunked and not self.damaged:
                # Records outside chunks are only believed in an unchunked file read without
                # damage so far: after damage, garbage may look like one.
                yield from self._records([record])
            at = end

    def _resume(self, buffer: mmap.mmap, at: int, cut: bool) -> int | None:
        """Where the walk goes on after what cannot be read at ``at`` (``None``: it stops).

        Args:
            buffer: The file.
            at: Where the unreadable record starts.
            cut: Whether the file ends inside it.

        Returns:
            The next intact chunk after ``at``, the file's end when there is none, or ``None``
            for a recording cut there (nothing damaged before it).
        """
        resume = self._next_chunk(buffer, at + 1)
        if resume is None and cut and not self.damaged:
            self._note_cut(at)
            return None
        stop = len(buffer) if resume is None else resume
        self.damaged.append(f'unreadable records at bytes {at}-{stop}')
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

    @staticmethod
    def _next_chunk(buffer: mmap.mmap, start: int) -> int | None:
        """Where the next intact chunk after ``start`` begins (``None``: there is none).

        The bytes are searched for a chunk's opcode where mcap reads a chunk whose length
        fits its content and whose CRC matches.
        """
        opcode = bytes([Opcode.CHUNK])
        at = buffer.find(opcode, start)
        while at != -1:
            if _intact_chunk_at(buffer, at):
                return at
            at = buffer.find(opcode, at + 1)
        return None

    # -- records ----------------------------------------------------------------------------

    def _records(
        self, records: Iterable[McapRecord]
    ) -> Iterator[tuple[Schema | None, Channel, Message]]:
        """The wanted messages among records; the schemas and channels among them defined."""
        for record in records:
            if isinstance(record, Message):
                channel = self.channels.get(record.channel_id)
                if channel is None or (
                    self.wanted is not None and channel.topic not in self.wanted
                ):
                    continue  # a message of a channel whose definition was lost is lost
                self.messages += 1
                yield self.schemas.get(channel.schema_id), channel, record
            elif isinstance(record, Schema):
                self.schemas.setdefault(record.id, record)
            elif isinstance(record, Channel):
                self._define_channel(record)

    def _define_channel(self, channel: Channel) -> None:
        self.channels.setdefault(channel.id, channel)
        if self.declared is not None:
            self.declared.setdefault(
                channel.topic, (self.schemas.get(channel.schema_id), self.channels[channel.id])
            )


def _intact_chunk_at(buffer: mmap.mmap, at: int) -> bool:
    """Whether an intact chunk record starts at ``at``."""
    prefix = ReadDataStream(io.BytesIO(buffer[at : at + _RECORD_PREFIX]))
    try:
        prefix.read1()
        length = prefix.read8()
    except _READ_ERRORS:
        return False
    # Most places that hold the opcode by chance declare a length the file cannot hold.
    if length < _CHUNK_FIELDS or at + _RECORD_PREFIX + length > len(buffer):
        return False
    read = _read_record(buffer, at)
    if read is None or not isinstance(read[0], Chunk) or read[1] != _chunk_end(at, read[0]):
        return False
    return _chunk_records(read[0]) is not None


def _raw(schema: Schema | None, channel: Channel, message: Message) -> RawMessage:
    msgtype = schema.name if schema is not None else channel.message_encoding
    return RawMessage(channel.topic, msgtype, message.log_time, message.data)


def open_bag(bag: str | Path | BagReader) -> BagReader:
    """Returns ``bag`` if it is already open, else opens it."""
    return bag if isinstance(bag, BagReader) else BagReader(bag)
