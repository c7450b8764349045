import numpy as np
import pytest

from lumpbeam_ros.bagio import BagReader, BagWriter, read_floats, read_tip_poses
from lumpbeam_ros.bagio.fastscan import decode_float64, decode_pose_stamped, scan_topic


def _write(path, frames=('beam_base',), n=50):
    with BagWriter(path) as bag:
        for i in range(n):
            bag.write_pose(
                '/tip_pose', 10.0 + i / 180, 2.3, -0.01 * i, 0.001 * i, frames[i % len(frames)]
            )
            bag.write_float('/tip_load', 10.0 + i / 180, 4.5)
    return path


def _general(path, topic='/tip_pose'):
    return read_tip_poses(path, topic, fast=False)


def test_fast_path_matches_the_general_reader(tmp_path):
    path = _write(tmp_path / 'bag')
    fast = read_tip_poses(path)
    general = _general(path)
    for name in ('t', 'x', 'z', 'pitch'):
        np.testing.assert_array_equal(getattr(fast, name), getattr(general, name))
    assert fast.frame_id == general.frame_id == 'beam_base'


def test_only_the_topic_asked_for(tmp_path):
    path = _write(tmp_path / 'bag', n=7)
    (file,) = BagReader(path).info.files
    log_times, payloads = scan_topic(file, '/tip_pose')
    assert len(payloads) == 7 and log_times[0] == 10_000_000_000
    assert scan_topic(file, '/nothing') == ([], [])


@pytest.mark.parametrize('payloads', [[], [b'\x00\x01\x00\x00' + b'\x00' * 10], [b'x' * 80]])
def test_unusual_payloads_go_to_the_general_decoder(payloads):
    assert decode_pose_stamped(payloads) is None


def test_mixed_frames_still_raise_through_the_general_reader(tmp_path):
    path = _write(tmp_path / 'bag', frames=('beam_base', 'camera'))
    with pytest.raises(Exception, match='frame'):
        read_tip_poses(path)


def test_a_cut_file_falls_back(tmp_path):
    path = _write(tmp_path / 'bag', n=200)
    (file,) = BagReader(path).info.files
    data = file.read_bytes()
    file.write_bytes(data[: len(data) // 2])
    assert scan_topic(file, '/tip_pose') is None
    # The general reader decides what survives a cut (see test_reader); both paths agree.
    np.testing.assert_array_equal(read_tip_poses(path).t, _general(path).t)


def test_float_series_match_the_general_reader(tmp_path):
    path = _write(tmp_path / 'bag', n=30)
    t, kg = read_floats(path, '/tip_load')
    assert len(t) == 30 and np.all(kg == 4.5)
    (file,) = BagReader(path).info.files
    _, payloads = scan_topic(file, '/tip_load')
    np.testing.assert_array_equal(decode_float64(payloads), kg)
    assert decode_float64([b'\x00\x01\x00\x00' + b'\x00' * 4]) is None
