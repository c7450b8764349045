import logging

import numpy as np
import pytest
import yaml
from mcap.reader import make_reader
from rosbags.rosbag2 import Reader

from lumpbeam_ros.base.errors import BagError
from lumpbeam_ros.core.bagio import BagReader, BagWriter, read_tip_poses, reindex, repair_bag
from lumpbeam_ros.core.bagio.repair import default_repair_path

from .helpers import T0, write_drop_bag

UNKNOWN_DEF = 'float64 value'


def _drop(path):
    write_drop_bag(path, images=3)


def _with_silent_topics(path):
    """A recording where two declared topics never published (a camera that never started)."""
    with BagWriter(path) as bag:
        bag.add_topic('/camera/camera_info', 'sensor_msgs/msg/CameraInfo')
        bag.add_topic('/tip_load', 'std_msgs/msg/Float64')
        for i in range(50):
            bag.write_pose('/tip_pose', T0 + i / 100, 2.3, -0.01 * i, 0.0)


def _with_an_unknown_type(path):
    """A topic of a type ROS 2 Jazzy lacks, and one more that never published."""
    with BagWriter(path) as bag:
        bag.add_topic('/custom', 'my_pkg/msg/Thing', msgdef=UNKNOWN_DEF, type_hash='RIHS01_ab')
        bag.add_topic('/silent', 'my_pkg/msg/Other', msgdef='int32 n', type_hash='RIHS01_cd')
        for i in range(5):
            bag.write_raw('/custom', 10 + i, b'\0\1\0\0' + np.float64(i).tobytes())
        bag.write_float('/tip_load', T0, 4.5)


BAGS = {'drop': _drop, 'silent topics': _with_silent_topics, 'unknown type': _with_an_unknown_type}


def _metadata(path):
    return yaml.safe_load((path / 'metadata.yaml').read_text())['rosbag2_bagfile_information']


def _topics(info):
    return {t['topic_metadata']['name']: t for t in info['topics_with_message_count']}


@pytest.fixture(params=sorted(BAGS))
def bag(request, tmp_path):
    path = tmp_path / 'bag'
    BAGS[request.param](path)
    return path


# -- reindex ---------------------------------------------------------------------------------


def test_reindex_rebuilds_the_metadata_the_writer_wrote(bag):
    original = _metadata(bag)
    (bag / 'metadata.yaml').unlink()
    assert reindex(bag) == original['message_count']
    rebuilt = _metadata(bag)
    for key in ('message_count', 'starting_time', 'duration', 'relative_file_paths', 'files'):
        assert rebuilt[key] == original[key], key
    before, after = _topics(original), _topics(rebuilt)
    assert set(after) == set(before)  # declared topics without messages included
    for name, entry in before.items():
        assert after[name]['message_count'] == entry['message_count'], name
        meta, meta_before = after[name]['topic_metadata'], entry['topic_metadata']
        assert meta['type'] == meta_before['type']
        assert meta['offered_qos_profiles'] == meta_before['offered_qos_profiles']
        if not meta['type'].startswith('my_pkg'):  # an unknown type's hash is not in the file
            assert meta['type_description_hash'] == meta_before['type_description_hash']


def test_reindexed_counts_agree_with_the_mcap_summary(bag):
    (bag / 'metadata.yaml').unlink()
    reindex(bag)
    with next(bag.glob('*.mcap')).open('rb') as stream:  # the mcap package reads the summary
        summary = make_reader(stream).get_summary()
    counts = summary.statistics.channel_message_counts
    counted = {c.topic: counts.get(i, 0) for i, c in summary.channels.items()}
    assert counted == {name: e.count for name, e in BagReader(bag).topics.items()}


def test_reindex_of_a_cut_file_counts_what_is_readable(tmp_path, caplog):
    write_drop_bag(tmp_path / 'cut')
    data_file = tmp_path / 'cut' / 'cut.mcap'
    data_file.write_bytes(data_file.read_bytes()[: data_file.stat().st_size // 2])
    readable = read_tip_poses(tmp_path / 'cut')  # the writer's metadata, a cut file
    (tmp_path / 'cut' / 'metadata.yaml').unlink()
    with caplog.at_level(logging.WARNING):
        found = reindex(tmp_path / 'cut')
    assert 'incomplete record' in caplog.text
    reader = BagReader(tmp_path / 'cut')
    assert reader.topics['/tip_pose'].count == readable.t.size
    assert 0 < readable.t.size < 720 and found == reader.info.message_count
    assert reader.info.start_ns == int(T0 * 1e9)
    np.testing.assert_array_equal(read_tip_poses(reader).t, readable.t)


@pytest.mark.parametrize(
    ('setup', 'match'),
    [
        ('missing', 'not a bag folder'),
        ('file', 'not a bag folder'),
        ('no data', r'exactly one \.mcap file, found 0'),
        ('two data', r'exactly one \.mcap file, found 2'),
    ],
)
def test_reindex_bad_input(tmp_path, setup, match):
    folder = tmp_path / 'b'
    if setup == 'file':
        folder.write_text('x')
    elif setup != 'missing':
        folder.mkdir()
        for i in range(2 if setup == 'two data' else 0):
            (folder / f'{i}.mcap').write_bytes(b'')
    with pytest.raises(BagError, match=match):
        reindex(folder)


def test_reindex_refuses_a_file_that_is_not_mcap(tmp_path):
    (tmp_path / 'b').mkdir()
    (tmp_path / 'b' / 'b.mcap').write_bytes(b'PK\3\4' * 8)
    with pytest.raises(BagError, match='not an MCAP file'):
        reindex(tmp_path / 'b')
    assert not (tmp_path / 'b' / 'metadata.yaml').exists()


# -- repair_bag ------------------------------------------------------------------------------


def test_a_whole_bag_is_copied_message_for_message(bag, tmp_path, mcap_doctor):
    summary = repair_bag(bag, tmp_path / 'copy')
    original, copy = BagReader(bag), BagReader(tmp_path / 'copy')
    assert not summary.truncated and summary.out == tmp_path / 'copy'
    assert summary.listed == summary.kept == {n: e.count for n, e in original.topics.items()}
    assert copy.topics == original.topics  # types, counts, QoS, type hashes
    assert [(r.topic, r.log_time_ns, bytes(r.data)) for r in copy.iter_raw()] == [
        (r.topic, r.log_time_ns, bytes(r.data)) for r in original.iter_raw()
    ]
    assert mcap_doctor(tmp_path / 'copy') == ''


def test_an_unknown_type_keeps_its_definition(tmp_path):
    _with_an_unknown_type(tmp_path / 'b')
    repair_bag(tmp_path / 'b', tmp_path / 'copy')
    with (tmp_path / 'copy' / 'copy.mcap').open('rb') as stream:
        schemas = make_reader(stream).get_summary().schemas.values()
    definitions = {s.name: (s.encoding, s.data.decode()) for s in schemas}
    assert definitions['my_pkg/msg/Thing'] == ('ros2msg', UNKNOWN_DEF)
    assert definitions['my_pkg/msg/Other'] == ('ros2msg', 'int32 n')  # declared, no message
    topics = BagReader(tmp_path / 'copy').topics
    assert (topics['/custom'].type_hash, topics['/silent'].type_hash) == ('RIHS01_ab', 'RIHS01_cd')
    assert (topics['/custom'].count, topics['/silent'].count) == (5, 0)


@pytest.mark.parametrize('keep', [0.25, 0.5, 0.9])
def test_a_cut_bag_becomes_whole_for_other_readers(tmp_path, keep, mcap_doctor):
    write_drop_bag(tmp_path / 'cut', images=3)
    data_file = tmp_path / 'cut' / 'cut.mcap'
    data_file.write_bytes(data_file.read_bytes()[: int(data_file.stat().st_size * keep)])
    readable = read_tip_poses(tmp_path / 'cut')
    summary = repair_bag(tmp_path / 'cut')
    assert summary.out == tmp_path / 'cut-repaired' and summary.truncated
    assert summary.listed['/tip_pose'] == 720  # the writer's last flushed metadata
    assert summary.kept['/tip_pose'] == readable.t.size < 720
    assert set(summary.kept) == set(summary.listed)  # every declared topic is in the copy
    with Reader(summary.out) as reader:  # rosbags needs the summary the cut file lacks
        counted = {c.topic: c.msgcount for c in reader.connections}
        stamps = [t for c, t, _ in reader.messages() if c.topic == '/tip_pose']
    assert counted == summary.kept
    np.testing.assert_allclose(np.array(stamps) * 1e-9, readable.t, rtol=0, atol=1e-6)
    assert mcap_doctor(summary.out) == ''


def test_default_repair_path_is_beside_the_bag():
    assert str(default_repair_path('/data/run_3')) == '/data/run_3-repaired'
    assert str(default_repair_path('/data/run_3/')) == '/data/run_3-repaired'


@pytest.mark.parametrize(
    ('bag_name', 'out_name', 'match'),
    [('missing', 'out', 'no such bag'), ('b', 'b', 'exists already')],
)
def test_repair_bad_input(tmp_path, bag_name, out_name, match):
    _drop(tmp_path / 'b')
    with pytest.raises(BagError, match=match):
        repair_bag(tmp_path / bag_name, tmp_path / out_name)
