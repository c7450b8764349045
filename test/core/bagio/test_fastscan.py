import io
import struct

import numpy as np
import pytest

from lumpbeam_ros.core.bagio import BagReader, BagWriter, read_floats, read_tip_poses
from lumpbeam_ros.core.bagio.convert import pose_values
from lumpbeam_ros.core.bagio.fastscan import decode_float64, decode_pose_stamped, message_record
from lumpbeam_ros.core.bagio.typestore import deserialize


def _write(path, frames=('beam_base',), n=50):
    with BagWriter(path) as bag:
        for i in range(n):
            bag.write_pose(
                '/tip_pose', 10.0 + i / 180, 2.3, -0.01 * i, 0.001 * i, frames[i % len(frames)]
            )
            bag.write_float('/tip_load', 10.0 + i / 180, 4.5)
    return path


def _payloads(path, topic):
    return [bytes(r.data) for r in BagReader(path).iter_raw([topic])]


def test_fast_path_matches_the_general_reader(tmp_path):
    path = _write(tmp_path / 'bag')
    fast = read_tip_poses(path)
    general = read_tip_poses(path, fast=False)
    for name in ('t', 'x', 'z', 'pitch'):
        np.testing.assert_array_equal(getattr(fast, name), getattr(general, name))
    assert fast.frame_id == general.frame_id == 'beam_base'


def test_the_vectorized_decoder_agrees_with_rosbags_message_for_message(tmp_path):
    payloads = _payloads(_write(tmp_path / 'bag', n=120), '/tip_pose')
    ns, position, orientation, frame = decode_pose_stamped(payloads)
    for i, data in enumerate(payloads):
        message = deserialize(data, 'geometry_msgs/msg/PoseStamped')
        stamp = message.header.stamp
        assert ns[i] == stamp.sec * 1_000_000_000 + stamp.nanosec
        p, q = message.pose.position, message.pose.orientation
        np.testing.assert_array_equal(position[i], [p.x, p.y, p.z])
        np.testing.assert_array_equal(orientation[i], [q.x, q.y, q.z, q.w])
        assert frame == message.header.frame_id
        assert pose_values(message)[4] == frame


@pytest.mark.parametrize('payloads', [[], [b'\x00\x01\x00\x00' + b'\x00' * 10], [b'x' * 80]])
def test_unusual_payloads_go_to_the_general_decoder(payloads):
    assert decode_pose_stamped(payloads) is None


def test_a_damaged_frame_id_goes_to_the_general_decoder(tmp_path):
    payloads = _payloads(_write(tmp_path / 'bag', n=5), '/tip_pose')
    damaged = bytearray(payloads[2])
    damaged[13] ^= 0xFF  # the frame id's length
    assert decode_pose_stamped([*payloads[:2], bytes(damaged), *payloads[3:]]) is None


def test_mixed_frames_still_raise_through_the_general_reader(tmp_path):
    path = _write(tmp_path / 'bag', frames=('beam_base', 'camera'))
    with pytest.raises(Exception, match='frame'):
        read_tip_poses(path)


def test_a_cut_file_reads_the_same_both_ways(tmp_path):
    path = _write(tmp_path / 'bag', n=200)
    (file,) = BagReader(path).info.files
    data = file.read_bytes()
    file.write_bytes(data[: len(data) // 2])
    np.testing.assert_array_equal(read_tip_poses(path).t, read_tip_poses(path, fast=False).t)


def test_float_series_match_the_general_reader(tmp_path):
    path = _write(tmp_path / 'bag', n=30)
    t, kg = read_floats(path, '/tip_load')
    assert len(t) == 30 and np.all(kg == 4.5)
    payloads = _payloads(path, '/tip_load')
    general = [deserialize(p, 'std_msgs/msg/Float64').data for p in payloads]
    np.testing.assert_array_equal(decode_float64(payloads), general)
    assert decode_float64([b'\x00\x01\x00\x00' + b'\x00' * 4]) is None


@pytest.mark.parametrize('size', [0, 1, 1_000_000])
def test_a_message_record_reads_as_mcaps_own_reader_reads_it(size):
    from mcap.data_stream import ReadDataStream
    from mcap.records import Message

    data = bytes(range(256)) * (size // 256) + bytes(size % 256)
    content = struct.pack('<HIQQ', 7, 2**31 + 5, 2**62 + 3, 11) + data
    padded = b'pad' + content + b'tail'
    ours = message_record(padded, 3, 3 + len(content))
    theirs = Message.read(ReadDataStream(io.BytesIO(content)), len(content))
    assert ours == theirs and isinstance(ours.data, bytes)
    assert message_record(padded, 3, 3 + 21) is None  # no room for the fields: mcap says why
