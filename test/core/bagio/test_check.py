"""The MCAP doctor: clean on what the product and the mcap package write.

Every check fails on a file broken in its way.
"""

from __future__ import annotations

import shutil
import struct
import subprocess
import sys
from collections import Counter
from collections.abc import Callable
from pathlib import Path

import pytest
import yaml
from mcap.data_stream import RecordBuilder
from mcap.reader import make_reader
from mcap.records import Channel, DataEnd, Footer, Header, Message, Schema
from mcap.writer import CompressionType, Writer

from core.bagio.helpers import write_drop_bag
from lumpbeam_ros.base.errors import BagError
from lumpbeam_ros.core.bagio import BagWriter
from lumpbeam_ros.core.bagio import check as doctor
from lumpbeam_ros.core.bagio.check import MAGIC, examine, examine_bag, examine_file
from lumpbeam_ros.core.bagio.reader import UnreadableRecordError, read_record_at

ROOT = Path(__file__).resolve().parents[3]
FOOTER_RECORD = 9 + 20  # opcode, length, summary_start, summary_offset_start, crc


@pytest.fixture(scope='module')
def synth_bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp('synth') / 'synth'
    subprocess.run(
        [sys.executable, '-m', 'lumpbeam_ros.apps.cli.main', 'synth', str(out), '--duration', '3'],
        check=True,
        capture_output=True,
        cwd=ROOT,
    )
    return out


@pytest.fixture(scope='module')
def writer_bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp('writer') / 'drop'
    write_drop_bag(out, images=40)
    return out


def mcap_file(bag: Path) -> Path:
    (file,) = sorted(bag.glob('*.mcap'))
    return file


def write_mcap(
    path: Path,
    log_times: list[int],
    compression: CompressionType = CompressionType.ZSTD,
    chunk_size: int = 200,
    profile: str = 'ros2',
    finish: bool = True,
    **options: bool,
) -> None:
    """Writes with the mcap package's own writer, in the order given (it does not sort)."""
    with path.open('wb') as stream:
        writer = Writer(stream, chunk_size=chunk_size, compression=compression, **options)
        writer.start(profile=profile, library='test')
        schema = writer.register_schema('std_msgs/msg/Float64', 'ros2msg', b'float64 data')
        channels = [writer.register_channel(t, 'cdr', schema) for t in ('/a', '/b')]
        for i, log_time in enumerate(log_times):
            payload = b'\x00\x01\x00\x00' + struct.pack('<d', i)
            writer.add_message(channels[i % 2], log_time, payload, log_time, i)
        if finish:
            writer.finish()
        else:
            writer.flush()


def summary_record(data: bytes, index: int) -> int:
    """The offset of a summary record (0: the first), walking lengths from summary_start."""
    (at,) = struct.unpack_from('<Q', data, len(data) - len(MAGIC) - FOOTER_RECORD + 9)
    for _ in range(index):
        at += 9 + struct.unpack_from('<Q', data, at + 1)[0]
    return at


def patch_u64(path: Path, at: int, delta: int) -> None:
    data = bytearray(path.read_bytes())
    struct.pack_into('<Q', data, at, struct.unpack_from('<Q', data, at)[0] + delta)
    path.write_bytes(bytes(data))


def build_records(path: Path, records: list) -> None:
    """A file of exactly these records (no summary), between the magic bytes."""
    builder = RecordBuilder()
    for record in records:
        record.write(builder)
    path.write_bytes(MAGIC + builder.end() + MAGIC)


# -- clean files ---------------------------------------------------------------------------


# The product's writer also flushes on wall-clock time, so these are least chunk counts.
@pytest.mark.parametrize(('bag_fixture', 'min_chunks'), [('synth_bag', 1), ('writer_bag', 20)])
def test_product_bags_are_clean(
    bag_fixture: str, min_chunks: int, request: pytest.FixtureRequest
) -> None:
    bag = request.getfixturevalue(bag_fixture)
    assert examine_bag(bag) == []
    # The mcap package's reader, independently, counts the same messages per topic.
    file = mcap_file(bag)
    report = examine(file)
    with file.open('rb') as stream:
        reader = make_reader(stream)
        summary = reader.get_summary()
        counted = Counter(channel.topic for _, channel, _ in reader.iter_messages())
    assert summary is not None and summary.statistics is not None
    assert report.topic_counts == dict(counted)
    assert summary.statistics.message_count == sum(counted.values()) > 500
    assert len(summary.chunk_indexes) == summary.statistics.chunk_count >= min_chunks
    assert report.profile == 'ros2'


@pytest.mark.parametrize('compression', list(CompressionType))
def test_mcap_package_files_in_order_are_clean(tmp_path: Path, compression) -> None:
    file = tmp_path / 'ok.mcap'
    write_mcap(file, list(range(1000, 1300, 3)), compression=compression, enable_data_crcs=True)
    assert examine_file(file) == []
    with file.open('rb') as stream:
        stats = make_reader(stream).get_summary().statistics
    assert (stats.message_count, stats.chunk_count) == (100, examine_chunk_count(file))


def examine_chunk_count(file: Path) -> int:
    """Chunks in a file according to its ChunkIndex records, read by the mcap package."""
    with file.open('rb') as stream:
        return len(make_reader(stream).get_summary().chunk_indexes)


# -- each check fails ----------------------------------------------------------------------


def out_of_order(path: Path) -> None:
    write_mcap(path, [100, 200, 150, 300, 250, 400])


def truncated(path: Path) -> None:
    write_mcap(path, list(range(0, 2000, 10)))
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])


def unfinished(path: Path) -> None:
    write_mcap(path, list(range(0, 2000, 10)), finish=False)


def corrupted_chunk(compression: CompressionType) -> Callable[[Path], None]:
    def build(path: Path) -> None:
        write_mcap(
            path,
            list(range(0, 2000, 10)),
            compression=compression,
            chunk_size=4000,
            repeat_schemas=False,
            repeat_channels=False,
        )
        data = bytearray(path.read_bytes())
        chunk_at = struct.unpack_from('<Q', data, summary_record(data, 1) + 9 + 16)[0]
        # Past the chunk's fixed fields and its compression string: inside the records.
        (name_length,) = struct.unpack_from('<I', data, chunk_at + 9 + 28)
        payload_at = chunk_at + 9 + 28 + 4 + name_length + 8
        for i in range(20, 60):
            data[payload_at + i] ^= 0x5A
        path.write_bytes(bytes(data))

    return build


def wrong_data_crc(path: Path) -> None:
    write_mcap(
        path,
        list(range(0, 2000, 10)),
        compression=CompressionType.NONE,
        enable_crcs=False,
        enable_data_crcs=True,
    )
    data = bytearray(path.read_bytes())
    data[len(data) // 3] ^= 0x01  # inside a message's payload (an uncompressed chunk)
    path.write_bytes(bytes(data))


def wrong_statistics(enable_crcs: bool) -> Callable[[Path], None]:
    def build(path: Path) -> None:
        write_mcap(
            path,
            list(range(0, 2000, 10)),
            repeat_schemas=False,
            repeat_channels=False,
            enable_crcs=enable_crcs,
        )
        patch_u64(path, summary_record(path.read_bytes(), 0) + 9, 1)  # message_count

    return build


def wrong_chunk_index(path: Path) -> None:
    write_mcap(path, list(range(0, 2000, 10)), repeat_schemas=False, repeat_channels=False)
    patch_u64(path, summary_record(path.read_bytes(), 1) + 9 + 8, -5)  # message_end_time


def wrong_chunk_times(path: Path) -> None:
    write_mcap(path, list(range(0, 2000, 10)), repeat_schemas=False, repeat_channels=False)
    data = path.read_bytes()
    chunk_at = struct.unpack_from('<Q', data, summary_record(data, 1) + 9 + 16)[0]
    patch_u64(path, chunk_at + 9, 3)  # the chunk's message_start_time


def wrong_message_index(path: Path) -> None:
    write_mcap(path, list(range(0, 2000, 10)), repeat_schemas=False, repeat_channels=False)
    data = path.read_bytes()
    index_at = summary_record(data, 1)
    # ChunkIndex: start, end, chunk offset, chunk length, then the offsets map (u32 length,
    # then channel id u16 and offset u64 per channel).
    (message_index_at,) = struct.unpack_from('<Q', data, index_at + 9 + 32 + 4 + 2)
    # MessageIndex: channel id u16, entries length u32, then (log time, offset) pairs.
    patch_u64(path, message_index_at + 9 + 2 + 4 + 8, 1)


def bad_profile(path: Path) -> None:
    write_mcap(path, [1, 2, 3], profile='ros7')


def channel_redefined(path: Path) -> None:
    schema = Schema(id=1, data=b'float64 data', encoding='ros2msg', name='std_msgs/msg/Float64')
    build_records(
        path,
        [
            Header('ros2', 'test'),
            schema,
            Channel(id=1, topic='/a', message_encoding='cdr', metadata={}, schema_id=1),
            Message(
                channel_id=2, log_time=5, data=b'\x00\x01\x00\x00', publish_time=5, sequence=0
            ),
            Channel(id=1, topic='/b', message_encoding='cdr', metadata={}, schema_id=1),
            DataEnd(0),
            Footer(0, 0, 0),
        ],
    )


def not_mcap(path: Path) -> None:
    path.write_bytes(b'just some bytes, not a recording')


BROKEN: dict[str, tuple[Callable[[Path], None], list[str]]] = {
    'out of order': (out_of_order, ['is less than the latest log time']),
    'truncated': (truncated, ['truncated']),
    'unfinished': (unfinished, ['without a Footer']),
    'corrupted chunk (none)': (corrupted_chunk(CompressionType.NONE), ['uncompressed_crc']),
    # A compressed chunk either fails to decompress or decompresses to records of another CRC.
    'corrupted chunk (zstd)': (corrupted_chunk(CompressionType.ZSTD), ['Chunk at offset']),
    'corrupted chunk (lz4)': (corrupted_chunk(CompressionType.LZ4), ['Chunk at offset']),
    'wrong data section crc': (wrong_data_crc, ['DataEnd.data_section_crc']),
    'wrong statistics': (wrong_statistics(False), ['Statistics.message_count 201 != 200']),
    'wrong statistics, summary crc': (
        wrong_statistics(True),
        ['Statistics.message_count 201 != 200', 'Footer.summary_crc'],
    ),
    'wrong chunk index': (wrong_chunk_index, ['ChunkIndex of the chunk at', 'message_end_time']),
    'wrong chunk times': (wrong_chunk_times, ["not its messages' least and greatest log time"]),
    'wrong message index': (wrong_message_index, ['points at no message']),
    'unknown profile': (bad_profile, ["Header.profile 'ros7' is not a well-known profile"]),
    'channel redefined': (
        channel_redefined,
        [
            'Message at offset',
            'is on channel 2, not defined before it',
            'Channel 1 ("/b") at offset',
            'redefines it differently',
            'no summary section',
        ],
    ),
    'not mcap': (not_mcap, ['not an MCAP file']),
}


@pytest.mark.parametrize('case', list(BROKEN))
def test_each_check_fails_on_its_broken_file(case: str, tmp_path: Path) -> None:
    build, expected = BROKEN[case]
    file = tmp_path / 'broken.mcap'
    build(file)
    problems = examine_file(file)
    text = '\n'.join(problems)
    for fragment in expected:
        assert fragment in text, text
    if case.startswith('corrupted chunk'):
        assert len(problems) == 1, text  # nothing that follows from the lost chunk


def test_out_of_order_names_each_message_and_nothing_else(tmp_path: Path) -> None:
    file = tmp_path / 'order.mcap'
    out_of_order(file)
    assert examine_file(file) == [
        'Message.log_time 150 on "/a" is less than the latest log time 200',
        'Message.log_time 250 on "/a" is less than the latest log time 300',
    ]


def test_a_flood_of_one_problem_is_capped(tmp_path: Path) -> None:
    file = tmp_path / 'backwards.mcap'
    write_mcap(file, list(range(1000, 0, -10)))
    problems = examine_file(file)
    assert len(problems) == doctor.MAX_LINES_PER_KIND + 1
    assert problems[-1] == f'... and {99 - doctor.MAX_LINES_PER_KIND} more log_time order problems'


def test_bag_metadata_counts_must_match(writer_bag: Path, tmp_path: Path) -> None:
    bag = tmp_path / 'bag'
    shutil.copytree(writer_bag, bag)
    path = bag / 'metadata.yaml'
    meta = yaml.safe_load(path.read_text())
    info = meta['rosbag2_bagfile_information']
    entry = info['topics_with_message_count'][0]
    entry['message_count'] += 2
    path.write_text(yaml.safe_dump(meta, sort_keys=False))
    topic = entry['topic_metadata']['name']
    count = entry['message_count']
    assert examine_bag(bag) == [
        f'metadata.yaml: {topic} message_count {count} != {count - 2}, in the files'
    ]


def test_bag_lines_name_the_file(writer_bag: Path, tmp_path: Path) -> None:
    bag = tmp_path / 'bag'
    shutil.copytree(writer_bag, bag)
    file = mcap_file(bag)
    data = file.read_bytes()
    file.write_bytes(data[: len(data) - 100])
    problems = examine_bag(bag)
    assert problems and problems[0].startswith(f'{file.name}: truncated')


def test_bad_input_is_one_clear_error(tmp_path: Path) -> None:
    with pytest.raises(BagError, match='missing.mcap'):
        examine_file(tmp_path / 'missing.mcap')
    with pytest.raises(BagError, match='not a bag folder'):
        examine_bag(tmp_path / 'nothing')
    with pytest.raises(BagError, match='neither metadata.yaml nor an .mcap file'):
        examine_bag(tmp_path)  # an empty folder: what doc/interfaces.md calls not a bag (2)
    (tmp_path / 'metadata.yaml').write_text('x')
    assert examine_bag(tmp_path) == [
        f'{tmp_path}: no .mcap file',
        f'{tmp_path}/metadata.yaml: not rosbag2 metadata (no rosbag2_bagfile_information)',
    ]


def test_a_message_that_does_not_decode_is_a_problem(tmp_path: Path) -> None:
    # Its chunk's CRC is right (the writer wrote the bad bytes): only decoding finds it.
    with BagWriter(tmp_path / 'b') as bag:
        bag.write_pose('/tip_pose', 1.0, 2.3, -0.01, 0.0)
        bag.add_topic('/tip_load', 'std_msgs/msg/Float64')
        bag.write_raw('/tip_load', 2 * 10**9, b'\0\1\0\0\7')
    [problem] = examine_bag(tmp_path / 'b')
    assert problem.startswith('b.mcap: Message at Chunk at offset ')
    assert 'on "/tip_load" does not decode: corrupt std_msgs/msg/Float64 message (5 bytes)' in (
        problem
    )


def test_bytes_overwritten_inside_a_message_fail_its_chunk_crc(writer_bag: Path, tmp_path):
    bag = tmp_path / 'bag'
    shutil.copytree(writer_bag, bag)
    file = mcap_file(bag)
    data = bytearray(file.read_bytes())
    # 8 bytes of one pose's z: the message still decodes, to a wrong value.
    at = data.index(b'beam_base\0', len(data) // 2) + 40
    data[at : at + 8] = struct.pack('<d', 2.208)
    file.write_bytes(bytes(data))
    crc, data_crc = examine_bag(bag)
    assert 'uncompressed_crc' in crc and 'DataEnd.data_section_crc' in data_crc


def test_an_empty_folder_is_not_a_bag(tmp_path: Path) -> None:
    (tmp_path / 'empty').mkdir()
    with pytest.raises(BagError, match='not a bag folder'):
        examine_bag(tmp_path / 'empty')


def test_a_chunk_length_beyond_an_index_is_an_unreadable_record():
    """A damaged chunk whose data length is about 1.2e19 raised OverflowError (fuzz case)."""
    body = struct.pack('<QQQI', 0, 0, 0, 0) + struct.pack('<I', 0) + struct.pack('<Q', 2**63 + 5)
    record = struct.pack('<BQ', 0x06, len(body)) + body  # a Chunk record holding it
    with pytest.raises(UnreadableRecordError, match='Chunk record at offset 8 does not parse'):
        read_record_at(record, 0, len(record), 'offset 8')
