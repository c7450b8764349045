import shutil
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from lumpbeam_ros.base.errors import BagError, LumpbeamError
from lumpbeam_ros.core.bagio import BagReader, BagWriter, read_tip_poses

from .helpers import write_drop_bag


def test_an_existing_bag_is_never_overwritten(tmp_path):
    write_drop_bag(tmp_path / 'drop')
    before = (tmp_path / 'drop' / 'drop.mcap').read_bytes()
    with pytest.raises(BagError, match='exists already'):
        BagWriter(tmp_path / 'drop')
    assert (tmp_path / 'drop' / 'drop.mcap').read_bytes() == before


def test_an_uncreatable_folder_is_a_clear_error(tmp_path):
    (tmp_path / 'file').write_text('not a folder')
    with pytest.raises(BagError, match='cannot create bag'):
        BagWriter(tmp_path / 'file' / 'bag')


@pytest.mark.parametrize(
    ('action', 'match'),
    [
        (lambda b: b.write_raw('/nope', 0, b'\0\1\0\0'), 'not declared'),
        (lambda b: b.add_topic('tip_pose', 'std_msgs/msg/Float64'), 'must start with /'),
        (lambda b: b.add_topic('/x', 'my_pkg/msg/Unknown'), 'unknown message type'),
        (lambda b: (b.write_float('/a', 0.0, 1.0), b.write_pose('/a', 0, 0, 0, 0)), 'carries'),
        (lambda b: b.write_float('/a', -1.0, 1.0), 'time must be'),
    ],
)
def test_bad_writes_are_clear_errors(tmp_path, action, match):
    with BagWriter(tmp_path / 'b') as bag, pytest.raises(BagError, match=match):
        action(bag)


def test_metadata_exists_while_writing_and_tracks_flushes(tmp_path):
    bag = BagWriter(tmp_path / 'live', flush_period_s=1e9)
    assert BagReader(tmp_path / 'live').topics == {}
    # 60 poses 1 ms apart: well inside a chunk's span, so only the flushes cut chunks.
    for i in range(50):
        bag.write_pose('/tip_pose', 1.0 + i / 1000, 2.0, -0.01 * i, 0.0)
    bag.flush()
    for i in range(50, 60):
        bag.write_pose('/tip_pose', 1.0 + i / 1000, 2.0, -0.01 * i, 0.0)
    # A copy now is what a SIGKILL would leave: flushed chunks, metadata of the last flush.
    shutil.copytree(tmp_path / 'live', tmp_path / 'killed')
    bag.close()
    killed = BagReader(tmp_path / 'killed')
    assert killed.truncated and killed.topics['/tip_pose'].count == 50
    np.testing.assert_array_equal(read_tip_poses(killed).t, 1.0 + np.arange(50) / 1000)
    assert read_tip_poses(tmp_path / 'live').t.size == 60


def test_the_flush_period_bounds_what_a_kill_loses(tmp_path):
    bag = BagWriter(tmp_path / 'live', flush_period_s=1e-6)  # every write is flushed
    for i in range(20):
        bag.write_float('/tip_load', float(i), 4.5)
    shutil.copytree(tmp_path / 'live', tmp_path / 'killed')
    bag.close()
    assert BagReader(tmp_path / 'killed').topics['/tip_load'].count == 20


def test_a_full_disk_keeps_what_was_flushed(tmp_path):
    # RLIMIT_FSIZE makes writes past 1.2 MB fail with EFBIG, as a full disk fails with ENOSPC.
    script = textwrap.dedent(
        f"""
        import resource, sys
        import numpy as np
        from lumpbeam_ros.core.bagio import BagWriter
        from lumpbeam_ros.base.errors import BagError
        resource.setrlimit(resource.RLIMIT_FSIZE, (1_200_000, 1_200_000))
        bag = BagWriter({str(tmp_path / 'full')!r}, flush_period_s=1e9)
        try:
            for i in range(100):
                bag.write_pose('/tip_pose', i / 1000, 2.0, 0.0, 0.0)
                bag.write_image('/camera/image_raw', i / 1000, np.full((200, 250), i, np.uint8))
                if i % 10 == 9:
                    bag.flush()
        except BagError as exc:
            print(exc)
            sys.exit(3)
        """
    )
    proc = subprocess.run([sys.executable, '-c', script], capture_output=True, text=True)
    assert proc.returncode == 3, proc.stderr
    assert (
        'File too large' in proc.stdout
        and 'the 40 messages flushed before are kept' in proc.stdout
    )
    reader = BagReader(tmp_path / 'full')
    poses = read_tip_poses(reader)
    assert reader.truncated and reader.topics['/tip_pose'].count == 20
    # Chunks close every ~1 MiB or flush, so the 20 flushed poses and maybe a few more survive.
    np.testing.assert_array_equal(poses.t[:20], np.arange(20.0) / 1000)


def test_messages_go_to_the_file_in_log_time_order(tmp_path, mcap_doctor):
    # Written out of order within one flush period: the file holds them sorted, ties in
    # the order written.
    with BagWriter(tmp_path / 'b', flush_period_s=60.0) as bag:
        for t, topic in [(3.0, '/a'), (1.0, '/b'), (2.0, '/a'), (1.0, '/a')]:
            bag.write_float(topic, t, t)
    from mcap.reader import make_reader

    with next((tmp_path / 'b').glob('*.mcap')).open('rb') as stream:
        got = [
            (m.log_time, c.topic)
            for _, c, m in make_reader(stream).iter_messages(log_time_order=False)
        ]
    assert got == [(1_000_000_000, '/b'), (1_000_000_000, '/a'), (2e9, '/a'), (3e9, '/a')]
    assert mcap_doctor(tmp_path / 'b') == ''


def test_a_message_older_than_what_was_flushed_is_kept_with_a_warning(tmp_path, caplog):
    with BagWriter(tmp_path / 'b') as bag:
        bag.write_float('/a', 2.0, 0.0)
        bag.flush()
        bag.write_float('/a', 2.0, 1.0)  # the same log time is still in order
        assert 'out of log-time order' not in caplog.text
        bag.write_float('/a', 1.0, 0.0)
    assert 'logged at 1000000000 ns comes after one logged at 2000000000 ns' in caplog.text
    assert BagReader(tmp_path / 'b').topics['/a'].count == 3


def test_an_offline_writer_gets_chunks_of_half_a_second(tmp_path):
    # Written faster than the flush period: chunks still span at most CHUNK_SPAN_NS of log
    # time, so one damaged chunk costs a reader half a second of data, not the bag.
    from mcap.reader import make_reader

    with BagWriter(tmp_path / 'b', flush_period_s=1e9) as bag:
        for i in range(1800):  # 10 s at 180 Hz
            bag.write_pose('/tip_pose', 100.0 + i / 180, 2.0, 0.0, 0.0)
    with (tmp_path / 'b' / 'b.mcap').open('rb') as stream:
        indexes = make_reader(stream).get_summary().chunk_indexes
    spans = [(i.message_end_time - i.message_start_time) * 1e-9 for i in indexes]
    assert 18 <= len(indexes) <= 21 and max(spans) < 0.5


def test_chunks_the_data_section_and_the_summary_carry_their_crcs(tmp_path):
    # A CRC of 0 means 'not computed': damage inside a message would then go unnoticed.
    import zlib

    from mcap.records import Chunk, DataEnd, Footer
    from mcap.stream_reader import StreamReader

    write_drop_bag(tmp_path / 'drop', images=3)
    data = (tmp_path / 'drop' / 'drop.mcap').read_bytes()
    with (tmp_path / 'drop' / 'drop.mcap').open('rb') as stream:
        records = list(StreamReader(stream, skip_magic=False, emit_chunks=True).records)
    chunks = [r for r in records if isinstance(r, Chunk)]
    assert len(chunks) >= 20 and all(c.compression == '' for c in chunks)
    assert [c.uncompressed_crc for c in chunks] == [zlib.crc32(c.data) for c in chunks]
    assert all(c.uncompressed_crc != 0 for c in chunks)
    [data_end] = [r for r in records if isinstance(r, DataEnd)]
    [footer] = [r for r in records if isinstance(r, Footer)]
    data_end_at = footer.summary_start - 13  # opcode, length, crc
    assert data_end.data_section_crc == zlib.crc32(data[:data_end_at]) != 0
    summary_crc_at = len(data) - 8 - 4  # the CRC precedes the closing magic
    assert footer.summary_crc == zlib.crc32(data[footer.summary_start : summary_crc_at]) != 0


def test_replace_bags_removes_a_bag_or_a_folder_of_bags_and_nothing_else(tmp_path):
    from lumpbeam_ros.core.bagio.metadata import is_bag
    from lumpbeam_ros.core.bagio.writer import replace_bags

    campaign = tmp_path / 'campaign'
    for name in ('a', 'b'):
        with BagWriter(campaign / name) as bag:
            bag.write_float('/tip_load', 0.0, 4.5)
    assert is_bag(campaign / 'a') and not is_bag(campaign)
    replace_bags(tmp_path / 'absent')  # nothing to replace
    replace_bags(campaign / 'a')
    assert not (campaign / 'a').exists() and (campaign / 'b').exists()
    replace_bags(campaign)
    assert not campaign.exists()
    other = tmp_path / 'other'
    other.mkdir()
    (other / 'x.txt').write_text('x')
    with pytest.raises(LumpbeamError, match='not a bag'):
        replace_bags(other)
    assert (other / 'x.txt').exists()
