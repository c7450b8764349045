"""A structural check of MCAP files and rosbag2 bags, the checks of ``mcap doctor`` (no ROS).

``mcap doctor`` (the Go CLI) cannot be installed everywhere, so this module makes the same
kind of checks in one pass over the records, read by the one record reader of the bags
(:func:`~lumpbeam_ros.core.bagio.reader.read_record_at`, mcap's record classes) and
decompressed by mcap (:func:`~lumpbeam_ros.core.bagio.reader.decompress_chunk`):

- the leading and trailing magic, every record parses and lies within the file (a cut file
  or a bad record is one problem, and the pass stops there), the Header first and a
  well-known profile (``ros2``: ``cdr`` messages, ``ros2msg``/``ros2idl`` schemas);
- schemas and channels defined before what uses them, an id never redefined differently;
- every chunk decompresses to its uncompressed size and CRC, and its message start and end
  times are the least and greatest log time of its messages;
- every message of a type the ROS 2 Jazzy typestore knows decodes (CDR), so damage inside
  a message is found in a file without CRCs too;
- messages' log times never decrease in file order (``Message.log_time X on "/topic" is less
  than the latest log time Y``, the doctor's warning);
- the message indexes after each chunk list exactly its messages, with their channels and
  log times;
- the data section CRC, the summary section: one chunk index per chunk that matches it, the
  statistics equal to what was counted, metadata/attachment indexes pointing at their
  records, the summary offsets and the footer pointing at their groups, and the summary CRC.

A file without a summary (a writer killed before closing it) is a problem too: the
product's bags must be whole. :func:`examine_bag` adds ``metadata.yaml``'s message counts.
"""

from __future__ import annotations

import mmap
import os
import zlib
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import BinaryIO

from mcap.opcode import Opcode
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

from lumpbeam_ros.base.errors import BagError
from lumpbeam_ros.core.bagio import metadata
from lumpbeam_ros.core.bagio.reader import (
    MAGIC,
    UnreadableRecordError,
    decompress_chunk,
    opcode_name,
    read_record_at,
)
from lumpbeam_ros.core.bagio.typestore import deserialize, is_known

#: Profiles of the MCAP registry; ``''`` is a file without one.
WELL_KNOWN_PROFILES = ('', 'ros1', 'ros2')
ROS2_SCHEMA_ENCODINGS = ('ros2msg', 'ros2idl')
#: Lines listed per kind of problem; the rest are counted in one line.
MAX_LINES_PER_KIND = 20

#: Where a Footer's summary CRC starts: after its opcode, length and two offsets.
_FOOTER_CRC_AT = 1 + 8 + 8 + 8
_SUMMARY_OPCODES = {
    Opcode.SCHEMA,
    Opcode.CHANNEL,
    Opcode.STATISTICS,
    Opcode.CHUNK_INDEX,
    Opcode.ATTACHMENT_INDEX,
    Opcode.METADATA_INDEX,
}
_CHUNK_OPCODES = {Opcode.SCHEMA, Opcode.CHANNEL, Opcode.MESSAGE}


class _UnreadableError(Exception):
    """The file cannot be read on from here (cut, or a record that does not parse)."""


@dataclass
class _ChunkSeen:
    """A chunk of the data section and the message indexes that follow it.

    Attributes:
        offset: File offset of the Chunk record.
        length: Record length, opcode and length field included.
        chunk: The record.
        messages: ``{offset in the uncompressed records: (channel id, log time)}``.
        index_offsets: File offset of each channel's Message Index record after the chunk.
        index_length: Bytes of the Message Index records after the chunk.
        indexed: ``(channel id, offset)`` of the entries of those Message Index records.
        readable: False when its records could not be read (a problem says why).
    """

    offset: int
    length: int
    chunk: Chunk
    messages: dict[int, tuple[int, int]] = field(default_factory=dict)
    index_offsets: dict[int, int] = field(default_factory=dict)
    index_length: int = 0
    indexed: set[tuple[int, int]] = field(default_factory=set)
    readable: bool = True


@dataclass
class FileReport:
    """What :func:`examine` found in one MCAP file.

    Attributes:
        problems: One line per problem (empty: clean).
        profile: The Header's profile (``None``: no readable Header).
        topic_counts: Messages counted per topic.
        complete: Whether every message could be counted (no unreadable chunk, not cut).
    """

    problems: list[str]
    profile: str | None
    topic_counts: dict[str, int]
    complete: bool = True


class _Examiner:
    """One pass over one MCAP file, collecting problems."""

    def __init__(self, data: mmap.mmap):
        self.data = data
        self.size = len(data)
        self.problems: list[str] = []
        self.kind_counts: Counter[str] = Counter()
        self.header: Header | None = None
        self.schemas: dict[int, Schema] = {}
        self.channels: dict[int, Channel] = {}
        self.message_count = 0
        self.channel_counts: Counter[int] = Counter()
        self.start_time: int | None = None
        self.end_time: int | None = None
        self.latest_time: int | None = None
        self.chunks: dict[int, _ChunkSeen] = {}
        # After an unreadable chunk, a missing definition may have been in it: not reported.
        self.lost_definitions = False
        self.indexing: _ChunkSeen | None = None  # the chunk whose message indexes may follow
        self.attachments: dict[int, int] = {}
        self.metadata: dict[int, tuple[int, str]] = {}
        self.data_crc = zlib.crc32(MAGIC)
        self.data_end_at: int | None = None
        self.summary: list[tuple[int, int, int]] = []  # (offset, end, opcode)
        self.summary_offsets: list[SummaryOffset] = []
        self.first_summary_offset_at: int | None = None
        self.statistics: list[Statistics] = []
        self.chunk_indexes: list[ChunkIndex] = []
        self.attachment_indexes: list[AttachmentIndex] = []
        self.metadata_indexes: list[MetadataIndex] = []
        self.summary_schemas: set[int] = set()
        self.summary_channels: set[int] = set()

    # -- reporting --------------------------------------------------------------------------

    def problem(self, kind: str, line: str) -> None:
        """Records a problem; beyond :data:`MAX_LINES_PER_KIND` of a kind only counts it."""
        self.kind_counts[kind] += 1
        if self.kind_counts[kind] <= MAX_LINES_PER_KIND:
            self.problems.append(line)

    def report(self) -> list[str]:
        """The problems, with one line per kind that had more than could be listed."""
        extra = [
            f'... and {n - MAX_LINES_PER_KIND} more {kind} problems'
            for kind, n in self.kind_counts.items()
            if n > MAX_LINES_PER_KIND
        ]
        return self.problems + extra

    def topic_counts(self) -> dict[str, int]:
        """Messages counted per topic."""
        counts: Counter[str] = Counter()
        for channel_id, n in self.channel_counts.items():
            channel = self.channels.get(channel_id)
            counts[channel.topic if channel else f'<channel {channel_id}>'] += n
        return dict(counts)

    # -- the pass ---------------------------------------------------------------------------

    def run(self) -> None:
        """Reads the file record by record and checks it (stops at the first unreadable part).

        Raises:
            _UnreadableError: The file is cut or holds a record that does not parse.
        """
        if self.data[: len(MAGIC)] != MAGIC:
            raise _UnreadableError('no MCAP magic at the start: not an MCAP file')
        offset = len(MAGIC)
        while True:
            if offset == self.size:
                raise _UnreadableError(
                    f'file ends at offset {offset} without a Footer: its writer did not '
                    'finish it (no summary, statistics or chunk indexes)'
                )
            try:
                opcode, record, end = read_record_at(
                    self.data, offset, self.size, f'offset {offset}'
                )
            except UnreadableRecordError as exc:
                raise _UnreadableError(f'truncated: {exc}' if exc.cut else str(exc)) from None
            if self.data_end_at is None and opcode != Opcode.DATA_END:
                self.data_crc = zlib.crc32(self.data[offset:end], self.data_crc)
            if opcode != Opcode.MESSAGE_INDEX:
                self.indexing = None
            if isinstance(record, Footer):
                self.on_footer(record, offset, end)
                return
            self.on_record(opcode, record, offset, end)
            offset = end

    def on_record(self, opcode: int, record: McapRecord | None, offset: int, end: int) -> None:
        """Checks one record before the Footer."""
        name = opcode_name(opcode)
        if self.header is None:
            if not isinstance(record, Header):
                raise _UnreadableError(
                    f'the first record is {name} at offset {offset}, not a Header'
                )
            self.on_header(record)
            return
        if isinstance(record, Header):
            self.problem('order', f'a second Header at offset {offset}')
        elif self.data_end_at is not None:
            self.on_summary_record(opcode, record, offset, end)
        elif isinstance(record, DataEnd):
            self.data_end_at = end
            if record.data_section_crc not in (0, self.data_crc):
                self.problem(
                    'crc',
                    f'DataEnd.data_section_crc {record.data_section_crc:#010x} != '
                    f'{self.data_crc:#010x}, the CRC of the data section',
                )
        elif isinstance(record, (Schema, Channel, Message)):
            self.on_content(record, f'offset {offset}')
        elif isinstance(record, Chunk):
            self.on_chunk(record, offset, end)
        elif isinstance(record, MessageIndex):
            self.on_message_index(record, offset, end)
        elif isinstance(record, Attachment):
            self.attachments[offset] = end - offset
        elif isinstance(record, Metadata):
            self.metadata[offset] = (end - offset, record.name)
        elif opcode in _SUMMARY_OPCODES or opcode == Opcode.SUMMARY_OFFSET:
            self.problem('order', f'{name} record at offset {offset} before the DataEnd')

    def on_header(self, header: Header) -> None:
        self.header = header
        if header.profile not in WELL_KNOWN_PROFILES:
            self.problem(
                'profile',
                f'Header.profile {header.profile!r} is not a well-known profile '
                f'({", ".join(repr(p) for p in WELL_KNOWN_PROFILES)})',
            )

    def on_content(self, record: Schema | Channel | Message, where: str) -> None:
        """Checks a Schema, Channel or Message of the data section (in a chunk or not)."""
        if isinstance(record, Message):
            self.on_message(record, where)
        elif isinstance(record, Schema):
            self.define_schema(record, where)
        else:
            self.define_channel(record, where)

    def define_schema(self, schema: Schema, where: str, in_summary: bool = False) -> None:
        if schema.id == 0:
            self.problem('schema', f'Schema at {where} has the reserved id 0')
            return
        known = self.schemas.get(schema.id)
        if known is not None and known != schema:
            self.problem(
                'schema', f'Schema {schema.id} at {where} redefines it differently ({known.name})'
            )
            return
        if known is None and in_summary:
            self.summary_schemas.add(schema.id)
        self.schemas.setdefault(schema.id, schema)
        profile = self.header.profile if self.header else ''
        if profile == 'ros2' and schema.encoding not in ROS2_SCHEMA_ENCODINGS:
            self.problem(
                'profile',
                f'Schema {schema.id} ({schema.name}) has encoding {schema.encoding!r}, '
                f'the ros2 profile needs one of {ROS2_SCHEMA_ENCODINGS}',
            )

    def define_channel(self, channel: Channel, where: str, in_summary: bool = False) -> None:
        label = f'Channel {channel.id} ("{channel.topic}") at {where}'
        known = self.channels.get(channel.id)
        if known is not None and known != channel:
            self.problem('channel', f'{label} redefines it differently ("{known.topic}")')
            return
        if (
            channel.schema_id != 0
            and channel.schema_id not in self.schemas
            and not self.lost_definitions
        ):
            self.problem(
                'channel', f'{label} uses schema {channel.schema_id}, not defined before it'
            )
        if known is None and in_summary:
            self.summary_channels.add(channel.id)
        self.channels.setdefault(channel.id, channel)
        profile = self.header.profile if self.header else ''
        if profile == 'ros2' and channel.message_encoding != 'cdr':
            self.problem(
                'profile',
                f'{label} has message encoding {channel.message_encoding!r}, '
                "the ros2 profile needs 'cdr'",
            )

    def on_message(self, message: Message, where: str) -> None:
        channel = self.channels.get(message.channel_id)
        if channel is None and not self.lost_definitions:
            self.problem(
                'channel',
                f'Message at {where} is on channel {message.channel_id}, not defined before it',
            )
        topic = channel.topic if channel else f'<channel {message.channel_id}>'
        schema = self.schemas.get(channel.schema_id) if channel is not None else None
        if schema is not None and is_known(schema.name):
            try:
                deserialize(message.data, schema.name)
            except BagError as exc:
                self.problem('message', f'Message at {where} on "{topic}" does not decode: {exc}')
        log_time = message.log_time
        if self.latest_time is not None and log_time < self.latest_time:
            self.problem(
                'log_time order',
                f'Message.log_time {log_time} on "{topic}" is less than the latest log time '
                f'{self.latest_time}',
            )
        self.latest_time = (
            log_time if self.latest_time is None else max(self.latest_time, log_time)
        )
        self.start_time = log_time if self.start_time is None else min(self.start_time, log_time)
        self.end_time = log_time if self.end_time is None else max(self.end_time, log_time)
        self.message_count += 1
        self.channel_counts[message.channel_id] += 1

    def on_chunk(self, chunk: Chunk, offset: int, end: int) -> None:
        """Decompresses a chunk and checks its size, CRC, records and time span."""
        label = f'Chunk at offset {offset}'
        seen = _ChunkSeen(offset=offset, length=end - offset, chunk=chunk)
        self.chunks[offset] = seen
        self.indexing = seen
        try:
            data = decompress_chunk(chunk)
        except UnreadableRecordError as exc:
            seen.readable = False
            self.lost_definitions = True
            self.problem('chunk', f'{label} does not decompress ({chunk.compression!r}: {exc})')
            return
        if len(data) != chunk.uncompressed_size:
            self.problem(
                'chunk',
                f'{label} decompresses to {len(data)} bytes, its uncompressed_size is '
                f'{chunk.uncompressed_size}',
            )
        crc = zlib.crc32(data)
        if chunk.uncompressed_crc not in (0, crc):
            self.problem(
                'crc',
                f'{label}: uncompressed_crc {chunk.uncompressed_crc:#010x} != {crc:#010x}, '
                'the CRC of its records',
            )
            seen.readable = False
            self.lost_definitions = True
            return  # its records are not what was written: reading them would only mislead
        self.chunk_records(seen, data)

    def chunk_records(self, seen: _ChunkSeen, data: bytes) -> None:
        label = f'Chunk at offset {seen.offset}'
        at = 0
        while at < len(data):
            where = f'{label} + {at}'
            try:
                opcode, record, end = read_record_at(data, at, len(data), where, ' in the chunk')
            except UnreadableRecordError as exc:
                raise _UnreadableError(str(exc)) from None
            if opcode not in _CHUNK_OPCODES:
                self.problem('order', f'{opcode_name(opcode)} record inside {where}')
            elif isinstance(record, (Schema, Channel, Message)):
                if isinstance(record, Message):
                    seen.messages[at] = (record.channel_id, record.log_time)
                self.on_content(record, where)
            at = end
        times = [t for _, t in seen.messages.values()]
        if times and (seen.chunk.message_start_time, seen.chunk.message_end_time) != (
            min(times),
            max(times),
        ):
            self.problem(
                'chunk',
                f'{label}: message_start_time {seen.chunk.message_start_time} and '
                f"message_end_time {seen.chunk.message_end_time} are not its messages' "
                f'least and greatest log time ({min(times)}, {max(times)})',
            )

    def on_message_index(self, index: MessageIndex, offset: int, end: int) -> None:
        """Checks a Message Index against the chunk it follows."""
        seen = self.indexing
        if seen is None:
            self.problem('index', f'MessageIndex at offset {offset} does not follow a Chunk')
            return
        label = f'MessageIndex at offset {offset} (channel {index.channel_id})'
        if index.channel_id in seen.index_offsets:
            self.problem('index', f'{label}: a second index of that channel for the chunk')
        seen.index_offsets[index.channel_id] = offset
        seen.index_length += end - offset
        if not seen.readable:
            return
        for log_time, at in index.records:
            found = seen.messages.get(at)
            if found != (index.channel_id, log_time):
                actual = 'no message' if found is None else f'channel {found[0]} at {found[1]}'
                self.problem(
                    'index',
                    f'{label}: entry (log time {log_time}, offset {at}) of the chunk at '
                    f'{seen.offset} points at {actual}',
                )
            seen.indexed.add((index.channel_id, at))

    def on_summary_record(
        self, opcode: int, record: McapRecord | None, offset: int, end: int
    ) -> None:
        """Collects a record of the summary or summary offset section."""
        where = f'summary offset {offset}'
        if isinstance(record, SummaryOffset):
            if self.first_summary_offset_at is None:
                self.first_summary_offset_at = offset
            self.summary_offsets.append(record)
            return
        if record is None:
            return  # an opcode of a later format version: readers skip it
        if opcode not in _SUMMARY_OPCODES:
            self.problem('order', f'{opcode_name(opcode)} record after the DataEnd, at {offset}')
            return
        if self.first_summary_offset_at is not None:
            self.problem('order', f'{opcode_name(opcode)} at {offset} after a SummaryOffset')
        self.summary.append((offset, end, opcode))
        if isinstance(record, Schema):
            self.define_schema(record, where, in_summary=True)
        elif isinstance(record, Channel):
            self.define_channel(record, where, in_summary=True)
        elif isinstance(record, Statistics):
            self.statistics.append(record)
        elif isinstance(record, ChunkIndex):
            self.chunk_indexes.append(record)
        elif isinstance(record, AttachmentIndex):
            self.attachment_indexes.append(record)
        elif isinstance(record, MetadataIndex):
            self.metadata_indexes.append(record)

    # -- the end of the file ----------------------------------------------------------------

    def on_footer(self, footer: Footer, offset: int, end: int) -> None:
        """Checks the trailing magic, the footer's offsets and CRC and the whole summary."""
        if self.data[end : end + len(MAGIC) + 1] != MAGIC:
            self.problem('magic', f'no MCAP magic (alone) after the Footer at offset {offset}')
        if self.data_end_at is None:
            self.problem('order', 'no DataEnd record before the Footer')
        self.check_messages_indexed()
        self.check_footer(footer, offset)
        if not self.summary:
            self.problem(
                'summary',
                'no summary section: no statistics or chunk indexes (an unfinished file)',
            )
            return
        self.check_summary_offsets()
        self.check_chunk_indexes()
        self.check_statistics()
        self.check_record_indexes()

    def check_messages_indexed(self) -> None:
        for seen in self.chunks.values():
            if seen.messages and not seen.index_offsets:
                self.problem('index', f'Chunk at offset {seen.offset} has no MessageIndex records')
                continue
            for at, (channel_id, _) in seen.messages.items():
                if seen.index_offsets and (channel_id, at) not in seen.indexed:
                    self.problem(
                        'index',
                        f'message at Chunk at offset {seen.offset} + {at} (channel {channel_id}) '
                        'is in none of its MessageIndex records',
                    )

    def check_footer(self, footer: Footer, offset: int) -> None:
        summary_at = self.summary[0][0] if self.summary else 0
        if footer.summary_start != summary_at:
            self.problem(
                'footer',
                f'Footer.summary_start {footer.summary_start} != {summary_at}, where the '
                'summary section starts (0: none)',
            )
        offsets_at = self.first_summary_offset_at or 0
        if footer.summary_offset_start != offsets_at:
            self.problem(
                'footer',
                f'Footer.summary_offset_start {footer.summary_offset_start} != {offsets_at}, '
                'where the summary offset section starts (0: none)',
            )
        if footer.summary_crc == 0:
            return
        # The summary CRC covers the summary sections and the Footer up to the CRC field.
        crc_from = footer.summary_start if 0 < footer.summary_start <= offset else offset
        crc = zlib.crc32(self.data[crc_from : offset + _FOOTER_CRC_AT])
        if crc != footer.summary_crc:
            self.problem(
                'crc', f'Footer.summary_crc {footer.summary_crc:#010x} != {crc:#010x}, computed'
            )

    def check_summary_offsets(self) -> None:
        starts = {start: i for i, (start, _, _) in enumerate(self.summary)}
        for group in self.summary_offsets:
            if group.group_length == 0:
                continue  # an empty group (the mcap package writes one per kind it has none of)
            name = opcode_name(group.group_opcode)
            label = f'SummaryOffset of {name} ({group.group_start}, +{group.group_length})'
            first = starts.get(group.group_start)
            if first is None:
                self.problem('summary', f'{label} does not start at a summary record')
                continue
            group_end = group.group_start + group.group_length
            records = [r for r in self.summary[first:] if r[1] <= group_end]
            if not records or records[-1][1] != group_end:
                self.problem('summary', f'{label} does not end at a record boundary')
            if any(opcode != group.group_opcode for _, _, opcode in records):
                self.problem('summary', f'{label} holds records of other kinds')
            expected = [r for r in self.summary if r[2] == group.group_opcode]
            if records != expected:
                self.problem('summary', f'{label} is not every {name} of the summary')

    def check_chunk_indexes(self) -> None:
        indexed: set[int] = set()
        for index in self.chunk_indexes:
            at = index.chunk_start_offset
            label = f'ChunkIndex of the chunk at {at}'
            seen = self.chunks.get(at)
            if seen is None:
                self.problem('chunk index', f'{label}: no Chunk starts there')
                continue
            if at in indexed:
                self.problem('chunk index', f'{label}: a second index of that chunk')
            indexed.add(at)
            chunk = seen.chunk
            expected = {
                'chunk_length': seen.length,
                'message_start_time': chunk.message_start_time,
                'message_end_time': chunk.message_end_time,
                'compression': chunk.compression,
                'compressed_size': len(chunk.data),
                'uncompressed_size': chunk.uncompressed_size,
                'message_index_offsets': seen.index_offsets,
                'message_index_length': seen.index_length,
            }
            for key, value in expected.items():
                if getattr(index, key) != value:
                    self.problem(
                        'chunk index', f'{label}: {key} {getattr(index, key)} != {value}, found'
                    )
        for at in self.chunks:
            if at not in indexed:
                self.problem('chunk index', f'Chunk at offset {at} has no ChunkIndex')

    def check_statistics(self) -> None:
        if len(self.statistics) != 1:
            self.problem(
                'statistics', f'{len(self.statistics)} Statistics records in the summary, not 1'
            )
        if not self.statistics:
            return
        if not all(seen.readable for seen in self.chunks.values()):
            return  # the counts miss an unreadable chunk's messages; that chunk is reported
        stats = self.statistics[0]
        counted: dict[str, int | None] = {
            'message_count': self.message_count,
            'schema_count': len(self.schemas),
            'channel_count': len(self.channels),
            'attachment_count': len(self.attachments),
            'metadata_count': len(self.metadata),
            'chunk_count': len(self.chunks),
        }
        if self.message_count:
            counted['message_start_time'] = self.start_time
            counted['message_end_time'] = self.end_time
        for key, value in counted.items():
            if getattr(stats, key) != value:
                self.problem(
                    'statistics', f'Statistics.{key} {getattr(stats, key)} != {value}, counted'
                )
        for channel_id in sorted(set(stats.channel_message_counts) | set(self.channel_counts)):
            written = stats.channel_message_counts.get(channel_id, 0)
            if written != self.channel_counts[channel_id]:
                self.problem(
                    'statistics',
                    f'Statistics.channel_message_counts[{channel_id}] {written} != '
                    f'{self.channel_counts[channel_id]}, counted',
                )

    def check_record_indexes(self) -> None:
        for index in self.metadata_indexes:
            found = self.metadata.get(index.offset)
            if found != (index.length, index.name):
                self.problem(
                    'index', f'MetadataIndex "{index.name}" at {index.offset} matches no Metadata'
                )
        for attachment_index in self.attachment_indexes:
            if self.attachments.get(attachment_index.offset) != attachment_index.length:
                self.problem(
                    'index',
                    f'AttachmentIndex "{attachment_index.name}" at {attachment_index.offset} '
                    'matches no Attachment',
                )


def _mapped(file: BinaryIO) -> mmap.mmap:
    """The file's bytes, mapped (an empty file maps to nothing: a one-byte stand-in)."""
    if os.fstat(file.fileno()).st_size == 0:
        stand_in = mmap.mmap(-1, 1)
        stand_in.resize(1)
        return stand_in
    return mmap.mmap(file.fileno(), 0, access=mmap.ACCESS_READ)


def examine(path: str | Path) -> FileReport:
    """Checks one MCAP file as ``mcap doctor`` does (see the module docstring).

    Args:
        path: The ``.mcap`` file.

    Returns:
        The problems found, the profile and the message count per topic.

    Raises:
        BagError: The file cannot be opened.
    """
    path = Path(path)
    try:
        file = path.open('rb')
    except OSError as exc:
        raise BagError(f'{path}: cannot open ({exc.strerror or exc})') from None
    complete = True
    with file, _mapped(file) as data:
        examiner = _Examiner(data)
        try:
            examiner.run()
        except _UnreadableError as exc:
            examiner.problems.append(str(exc))
            complete = False
    complete = complete and all(seen.readable for seen in examiner.chunks.values())
    profile = examiner.header.profile if examiner.header else None
    return FileReport(examiner.report(), profile, examiner.topic_counts(), complete)


def examine_file(path: str | Path) -> list[str]:
    """Lists every problem of one MCAP file, one line each (see the module docstring).

    Args:
        path: The ``.mcap`` file.

    Returns:
        The problems; an empty list for a clean file.

    Raises:
        BagError: The file cannot be opened.
    """
    return examine(path).problems


def examine_bag(bag: str | Path) -> list[str]:
    """Lists every problem of a rosbag2 bag: its ``.mcap`` files and ``metadata.yaml``.

    Each file's lines start with the file's name. The files must have the ``ros2`` profile,
    and ``metadata.yaml`` must list, per topic, the messages the files hold.

    Args:
        bag: The bag folder.

    The counts are compared only when every message of the files could be counted: a
    damaged chunk is reported as such, not again as a count that differs.

    Returns:
        The problems; an empty list for a clean bag.

    Raises:
        BagError: Not a bag folder (no folder, or one with neither ``metadata.yaml`` nor an
            ``.mcap`` file), or a file that cannot be opened.
    """
    folder = Path(bag)
    if not folder.is_dir():
        raise BagError(f'{folder}: not a bag folder')
    problems: list[str] = []
    files = sorted(folder.glob('*.mcap'))
    if not files and not (folder / metadata.FILENAME).exists():
        raise BagError(
            f'{folder}: not a bag folder (neither {metadata.FILENAME} nor an .mcap file)'
        )
    if not files:
        problems.append(f'{folder}: no .mcap file')
    counts: Counter[str] = Counter()
    complete = True
    for file in files:
        report = examine(file)
        problems += [f'{file.name}: {line}' for line in report.problems]
        if report.profile not in (None, 'ros2'):
            problems.append(f"{file.name}: Header.profile {report.profile!r}, a bag needs 'ros2'")
        counts.update(report.topic_counts)
        complete = complete and report.complete
    try:
        info = metadata.load(folder)
    except BagError as exc:
        return [*problems, str(exc)]
    if not complete:
        return problems
    listed = {entry.name: entry.count for entry in info.topics.values()}
    for topic in sorted(set(listed) | set(counts)):
        if topic not in listed:
            problems.append(
                f'{metadata.FILENAME}: topic {topic} ({counts[topic]} messages) missing'
            )
        elif listed[topic] != counts[topic]:
            problems.append(
                f'{metadata.FILENAME}: {topic} message_count {listed[topic]} != '
                f'{counts[topic]}, in the files'
            )
    if info.message_count != sum(counts.values()):
        problems.append(
            f'{metadata.FILENAME}: message_count {info.message_count} != '
            f'{sum(counts.values())}, in the files'
        )
    return problems
