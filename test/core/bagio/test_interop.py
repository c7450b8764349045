import numpy as np
import pytest
import yaml
from mcap.reader import make_reader
from mcap_ros2.decoder import DecoderFactory
from rosbags.rosbag2 import Reader
from rosbags.typesys import Stores, get_typestore

from lumpbeam_ros.core.bagio.qos import SENSOR_DEPTH

from .helpers import T0, write_drop_bag


@pytest.fixture(scope='module')
def drop(tmp_path_factory):
    path = tmp_path_factory.mktemp('interop') / 'drop'
    return path, write_drop_bag(path, images=4)


def test_rosbags_reads_every_topic(drop):
    path, s = drop
    store = get_typestore(Stores.ROS2_JAZZY)
    with Reader(path) as reader:
        counts = {c.topic: c.msgcount for c in reader.connections}
        assert counts == {'/tip_pose': 720, '/tip_load': 40, '/camera/image_raw': 4}
        poses = [c for c in reader.connections if c.topic == '/tip_pose']
        z = [
            store.deserialize_cdr(data, c.msgtype).pose.position.z
            for c, _, data in reader.messages(connections=poses)
        ]
    np.testing.assert_array_equal(z, s['z'])


def test_mcap_ros2_decodes_with_the_stored_definitions(drop):
    path, s = drop
    with (path / 'drop.mcap').open('rb') as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        decoded = list(reader.iter_decoded_messages(topics=['/tip_pose', '/camera/image_raw']))
    poses = [d for _, c, _, d in decoded if c.topic == '/tip_pose']
    images = [d for _, c, _, d in decoded if c.topic == '/camera/image_raw']
    assert poses[0].header.frame_id == 'beam_base'
    assert poses[0].header.stamp.sec == int(T0)
    np.testing.assert_allclose([p.pose.position.z for p in poses], s['z'])
    assert (images[3].encoding, images[3].height, images[3].width) == ('mono8', 8, 10)
    assert bytes(images[3].data) == bytes([3]) * 80
    assert all(schema.encoding == 'ros2msg' for schema, _, _, _ in decoded)


def test_metadata_has_what_ros2_bag_info_expects(drop):
    path, _ = drop
    info = yaml.safe_load((path / 'metadata.yaml').read_text())['rosbag2_bagfile_information']
    assert info['version'] == 9 and info['storage_identifier'] == 'mcap'
    assert info['relative_file_paths'] == ['drop.mcap'] and (path / 'drop.mcap').is_file()
    assert info['message_count'] == 764
    assert info['starting_time']['nanoseconds_since_epoch'] == int(T0 * 1e9)
    assert info['duration']['nanoseconds'] == pytest.approx((719 / 180) * 1e9, abs=1e3)
    assert info['files'][0]['path'] == 'drop.mcap' and info['files'][0]['message_count'] == 764
    topics = {t['topic_metadata']['name']: t for t in info['topics_with_message_count']}
    pose = topics['/tip_pose']
    assert pose['message_count'] == 720
    assert pose['topic_metadata']['type'] == 'geometry_msgs/msg/PoseStamped'
    assert pose['topic_metadata']['serialization_format'] == 'cdr'
    assert pose['topic_metadata']['type_description_hash'].startswith('RIHS01_')
    image_qos = topics['/camera/image_raw']['topic_metadata']['offered_qos_profiles'][0]
    assert (image_qos['reliability'], image_qos['history'], image_qos['depth']) == (
        'best_effort',
        'keep_last',
        SENSOR_DEPTH,
    )
