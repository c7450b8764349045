"""metadata.yaml as rosbags reads it, and every way a bag folder can be unusable."""

import pytest
import yaml
from rosbags.rosbag2 import Reader

from lumpbeam_ros.base.errors import BagError
from lumpbeam_ros.core.bagio import BagWriter, metadata
from lumpbeam_ros.core.bagio.qos import default_profile, from_dict

POSE = 'geometry_msgs/msg/PoseStamped'
FLOAT = 'std_msgs/msg/Float64'


@pytest.fixture
def bag(tmp_path):
    """A bag of 3 poses and 2 loads; its metadata.yaml is rewritten by the tests."""
    folder = tmp_path / 'bag'
    with BagWriter(folder) as writer:
        for i in range(3):
            writer.write_pose('/tip_pose', 1.0 + 0.5 * i, 0.1, -0.01 * i, 0.0)
        writer.write_float('/tip_load', 1.0, 4.5)
        writer.write_float('/tip_load', 2.0, 0.0)
    return folder


def _rebuild(folder, start_ns, end_ns):
    data_file = next(folder.glob('*.mcap')).name
    topics = [
        ('/tip_pose', POSE, 3, [default_profile('/tip_pose', POSE)], ''),
        ('/tip_load', FLOAT, 2, [default_profile('/tip_load', FLOAT)], 'RIHS01_abc'),
    ]
    built = metadata.build(data_file, topics, start_ns, end_ns)
    metadata.write(folder, built)
    return built


def test_built_metadata_reads_back_through_rosbags(bag):
    start, end = 1_000_000_000, 2_000_000_000
    _rebuild(bag, start, end)
    with Reader(bag) as reader:
        assert reader.message_count == 5
        assert (reader.start_time, reader.end_time) == (start, end + 1)  # rosbags: end exclusive
        assert {c.topic: (c.msgtype, c.msgcount) for c in reader.connections} == {
            '/tip_pose': (POSE, 3),
            '/tip_load': (FLOAT, 2),
        }
        qos = {c.topic: c.ext.offered_qos_profiles for c in reader.connections}
    assert qos['/tip_load'] == [default_profile('/tip_load', FLOAT)]
    assert qos['/tip_pose'] == [default_profile('/tip_pose', POSE)]


def test_load_returns_what_build_wrote(bag):
    _rebuild(bag, 5, 105)
    info = metadata.load(bag)
    assert (info.start_ns, info.duration_ns, info.message_count) == (5, 100, 5)
    assert [f.parent for f in info.files] == [bag] and all(f.is_file() for f in info.files)
    load = info.topics['/tip_load']
    assert (load.msgtype, load.count, load.type_hash) == (FLOAT, 2, 'RIHS01_abc')
    assert [from_dict(p) for p in load.qos] == [default_profile('/tip_load', FLOAT)]
    assert info.topics['/tip_pose'].type_hash == ''


def test_an_empty_bag_has_no_time_span():
    built = metadata.build('x.mcap', [('/a', FLOAT, 0, [], '')], 7, 9)
    info = built['rosbag2_bagfile_information']
    assert info['duration'] == {'nanoseconds': 0}
    assert info['starting_time'] == {'nanoseconds_since_epoch': 0}
    assert info['version'] == metadata.VERSION == 9


def test_version_8_qos_as_a_yaml_string_is_read(bag):
    built = _rebuild(bag, 0, 10)
    topic = built['rosbag2_bagfile_information']['topics_with_message_count'][0]
    profiles = topic['topic_metadata']['offered_qos_profiles']
    topic['topic_metadata']['offered_qos_profiles'] = yaml.safe_dump(profiles)
    built['rosbag2_bagfile_information']['version'] = 8
    metadata.write(bag, built)
    assert metadata.load(bag).topics['/tip_pose'].qos == profiles


def _edit(bag, change):
    built = _rebuild(bag, 0, 10)
    change(built['rosbag2_bagfile_information'])
    metadata.write(bag, built)


@pytest.mark.parametrize(
    ('change', 'message'),
    [
        (lambda i: i.update(storage_identifier='sqlite3'), "storage 'sqlite3' is not supported"),
        (lambda i: i.update(compression_mode='file'), 'file compression is not supported'),
        (lambda i: i.pop('relative_file_paths'), 'malformed rosbag2 metadata (KeyError'),
        (lambda i: i.update(message_count='many'), 'malformed rosbag2 metadata (ValueError'),
        (lambda i: i.update(relative_file_paths=[]), 'lists no data files'),
        (lambda i: i.update(relative_file_paths=['gone.mcap']), 'data file gone.mcap'),
    ],
)
def test_unusable_metadata_is_named(bag, change, message):
    _edit(bag, change)
    with pytest.raises(BagError) as caught:
        metadata.load(bag)
    assert message in str(caught.value)
    assert str(bag) in str(caught.value)


@pytest.mark.parametrize(
    ('text', 'message'),
    [
        ('a: [1\n', 'unreadable metadata'),
        ('- 1\n', 'not rosbag2 metadata'),
        ('rosbag2_bagfile_information: 3\n', 'not rosbag2 metadata'),
    ],
)
def test_unreadable_metadata_file(bag, text, message):
    (bag / metadata.FILENAME).write_text(text)
    with pytest.raises(BagError, match=message):
        metadata.load(bag)


def test_not_a_bag_folder(tmp_path):
    with pytest.raises(BagError, match='no such bag'):
        metadata.load(tmp_path / 'absent')
    (tmp_path / 'file').write_text('x')
    with pytest.raises(BagError, match='not a bag folder'):
        metadata.load(tmp_path / 'file')
    with pytest.raises(BagError, match=r'not a rosbag2 bag \(no metadata.yaml\)'):
        metadata.load(tmp_path)
