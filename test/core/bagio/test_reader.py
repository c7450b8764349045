import logging

import numpy as np
import pytest
import yaml

from lumpbeam_ros.base.errors import BagError
from lumpbeam_ros.core.bagio import BagReader, BagWriter, read_load_events, read_tip_poses, reindex
from lumpbeam_ros.core.bagio.reader import FileWalk

from .helpers import T0, write_drop_bag


@pytest.fixture
def drop(tmp_path):
    write_drop_bag(tmp_path / 'drop')
    return tmp_path / 'drop'


def test_not_a_bag(tmp_path):
    (tmp_path / 'plain.txt').write_text('x')
    (tmp_path / 'folder').mkdir()
    for path, match in [
        (tmp_path / 'missing', 'no such bag'),
        (tmp_path / 'plain.txt', 'not a bag folder'),
        (tmp_path / 'folder', r'not a rosbag2 bag \(no metadata.yaml\)'),
    ]:
        with pytest.raises(BagError, match=match):
            BagReader(path)


@pytest.mark.parametrize(
    ('text', 'match'),
    [
        ('a: [unclosed', 'unreadable metadata'),
        ('just a string', 'no rosbag2_bagfile_information'),
        ('rosbag2_bagfile_information: {storage_identifier: mcap}', 'malformed'),
        ('rosbag2_bagfile_information: {storage_identifier: sqlite3}', 'only mcap'),
    ],
)
def test_corrupt_metadata(drop, text, match):
    (drop / 'metadata.yaml').write_text(text)
    with pytest.raises(BagError, match=match):
        BagReader(drop)


def test_a_listed_data_file_that_is_missing(drop):
    (drop / 'drop.mcap').unlink()
    with pytest.raises(BagError, match='data file drop.mcap listed in metadata.yaml is missing'):
        BagReader(drop)


@pytest.mark.parametrize(('content', 'match'), [(b'', 'is empty'), (b'PK\3\4' * 8, 'not an MCAP')])
def test_empty_or_foreign_data_file(drop, content, match):
    (drop / 'drop.mcap').write_bytes(content)
    with pytest.raises(BagError, match=match):
        BagReader(drop)


@pytest.mark.parametrize('keep', [0.3, 0.6, 0.8])
def test_a_truncated_file_reads_what_is_readable_and_warns(drop, keep, caplog):
    full = read_tip_poses(drop)
    data = (drop / 'drop.mcap').read_bytes()
    (drop / 'drop.mcap').write_bytes(data[: int(len(data) * keep)])
    with caplog.at_level(logging.WARNING):
        poses = read_tip_poses(drop)
    assert 'no closing index' in caplog.text and 'incomplete record' in caplog.text
    # A cut file keeps a prefix of whole chunks: fewer poses, identical to the first ones.
    assert 0 < poses.t.size < full.t.size
    np.testing.assert_array_equal(poses.z, full.z[: poses.t.size])


def test_a_file_cut_inside_its_header_has_no_messages(drop, caplog):
    data = (drop / 'drop.mcap').read_bytes()
    (drop / 'drop.mcap').write_bytes(data[:12])
    assert read_tip_poses(drop).t.size == 0
    assert 'kept 0 messages' in caplog.text


def test_an_unknown_message_type_is_read_raw_but_not_decoded(tmp_path):
    with BagWriter(tmp_path / 'b') as bag:
        bag.add_topic('/custom', 'my_pkg/msg/Thing', msgdef='float64 value', type_hash='RIHS01_00')
        bag.write_raw('/custom', 5, b'\0\1\0\0' + np.float64(2.5).tobytes())
    reader = BagReader(tmp_path / 'b')
    [raw] = reader.iter_raw()
    assert (raw.topic, raw.msgtype, raw.log_time_ns) == ('/custom', 'my_pkg/msg/Thing', 5)
    with pytest.raises(BagError, match="unknown message type 'my_pkg/msg/Thing'"):
        list(reader.messages('/custom', 'my_pkg/msg/Thing'))


@pytest.mark.parametrize('fast', [True, False])
def test_an_undecodable_message_is_a_counted_named_loss(tmp_path, caplog, fast):
    # One bad message among good ones: skipped and counted, not the whole bag rejected.
    with BagWriter(tmp_path / 'b') as bag:
        for i in range(5):
            bag.write_pose('/tip_pose', 1.0 + i, 2.3, -0.01 * i, 0.0)
        bag.write_raw('/tip_pose', 6 * 10**9, b'\0\1\0\0\7')
    with caplog.at_level(logging.WARNING):
        poses = read_tip_poses(tmp_path / 'b', fast=fast)
    np.testing.assert_array_equal(poses.t, 1.0 + np.arange(5))
    [line] = [r.getMessage() for r in caplog.records]
    assert line.startswith(f'{tmp_path / "b"}: /tip_pose: lost 1 of the 6 messages')
    assert '1 undecodable: corrupt geometry_msgs/msg/PoseStamped message (5 bytes)' in line
    assert BagReader(tmp_path / 'b').topics['/tip_pose'].count == 6


def test_reindex_rebuilds_lost_metadata(drop):
    original = yaml.safe_load((drop / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    (drop / 'metadata.yaml').unlink()
    assert reindex(drop) == original['message_count']
    rebuilt = BagReader(drop)
    assert rebuilt.info.message_count == original['message_count']
    assert rebuilt.info.start_ns == original['starting_time']['nanoseconds_since_epoch']
    assert rebuilt.topics['/tip_load'].qos[0]['durability'] == 'transient_local'
    np.testing.assert_array_equal(read_load_events(rebuilt).changes().kg, [4.5, 0.0])
    with pytest.raises(BagError, match='exactly one .mcap'):
        reindex(drop.parent)


@pytest.mark.parametrize('fast', [True, False])
def test_messages_lost_to_damaged_bytes_are_named_with_their_count(drop, caplog, fast):
    # 4 KB of random bytes in the middle of the data file: the readers skip what those
    # chunks held; the bag's own counts (metadata.yaml) tell how much that was.
    data_file = next(drop.glob('*.mcap'))
    data = bytearray(data_file.read_bytes())
    middle = len(data) // 2
    data[middle : middle + 4096] = np.random.default_rng(1).bytes(4096)
    data_file.write_bytes(bytes(data))
    listed = BagReader(drop).topics['/tip_pose'].count
    with caplog.at_level(logging.WARNING):
        poses = read_tip_poses(drop, fast=fast)
    lost = listed - len(poses.t)
    assert 0 < lost < listed
    assert f'/tip_pose: lost {lost} of the {listed} messages' in caplog.text
    assert f'({lost} in damaged data)' in caplog.text


def test_an_intact_bag_reads_without_a_loss_warning(drop, caplog):
    with caplog.at_level(logging.WARNING):
        assert len(read_tip_poses(drop).t) == BagReader(drop).topics['/tip_pose'].count
        assert len(list(BagReader(drop).iter_raw())) == BagReader(drop).info.message_count
    assert 'lost' not in caplog.text


def test_a_sparse_topic_is_read_from_its_own_chunks_only(tmp_path, monkeypatch):
    # A load reading before and after the release, poses throughout: 20 chunks.
    bag = tmp_path / 'sparse'
    with BagWriter(bag) as writer:
        for i in range(720):
            writer.write_pose('/tip_pose', T0 + i / 180.0, 0.0, -0.05, 0.0)
            if i in (0, 360):
                writer.write_float('/tip_load', T0 + i / 180.0, 4.5 if i == 0 else 0.0)
            if i % 36 == 35:
                writer.flush()
    opened = []
    walk = FileWalk._indexed_chunk

    def counted(buffer, index):
        opened.append(index.chunk_start_offset)
        return walk(buffer, index)

    monkeypatch.setattr(FileWalk, '_indexed_chunk', staticmethod(counted))
    assert len(read_tip_poses(bag).t) == 720
    assert len(opened) == 20
    opened.clear()
    np.testing.assert_array_equal(read_load_events(bag).kg, [4.5, 0.0])
    assert len(opened) == 2


def test_a_damaged_summary_is_not_trusted_and_every_message_is_still_read(drop, caplog):
    full = read_tip_poses(drop)
    data_file = drop / 'drop.mcap'
    data = bytearray(data_file.read_bytes())
    data[-(8 + 29) - 5] ^= 0xFF  # in the summary, just before the footer: its CRC fails
    data_file.write_bytes(bytes(data))
    with caplog.at_level(logging.WARNING):
        poses = read_tip_poses(drop)
    assert 'no closing index' in caplog.text and 'lost' not in caplog.text
    np.testing.assert_array_equal(poses.z, full.z)
