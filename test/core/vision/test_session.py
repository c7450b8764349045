"""A camera stream through a tracking session: intrinsics, frames, messages and the tally."""

import dataclasses
import math

import numpy as np
import pytest

from lumpbeam_lab.camera.accuracy import render_frames
from lumpbeam_ros.base.errors import BagError, LumpbeamError
from lumpbeam_ros.base.interface import COMPRESSED_IMAGE_TYPE
from lumpbeam_ros.core.bagio import convert
from lumpbeam_ros.core.bagio.typestore import serialize
from lumpbeam_ros.core.vision.messages import camera_info_to_data
from lumpbeam_ros.core.vision.session import SessionStats, TrackingSession
from lumpbeam_ros.core.vision.tracker import TrackStatus

from .helpers import compressed_cdr, encoded, image_cdr


@pytest.fixture(scope='module')
def frames(config, drop_test):
    """Six frames across the release (640 x 480)."""
    return render_frames(config, drop_test.between(1.98, 2.1), 6)


@pytest.fixture
def session(config, no_calibration):
    return TrackingSession(no_calibration, config.camera_info)


def test_frames_give_poses_on_the_truth(session, frames):
    results = [session.process(f.image, f.stamp) for f in frames]
    assert all(r.ok for r in results)
    errors = np.array([r.pose - f.truth for r, f in zip(results, frames, strict=True)])
    assert np.max(np.abs(errors[:, 1])) < 50e-6  # z, m
    stats = session.stats
    assert (stats.frames_in, stats.poses_out, stats.frames_lost) == (6, 6, 0)
    assert stats.last_stamp == frames[-1].stamp and stats.lost == {}


def test_without_intrinsics_every_frame_waits_for_them(config, no_calibration, frames):
    session = TrackingSession(no_calibration)
    assert session.camera_info is None and session.tracker is None
    result = session.process(frames[0].image, frames[0].stamp)
    assert result.status == TrackStatus.NO_CAMERA_INFO and result.pose is None
    assert result.reason == 'no camera_info received yet'
    assert session.stats.lost == {'no_camera_info': 1}
    assert session.stats.last_reason == 'no camera_info received yet'
    assert session.set_camera_info(config.camera_info) is True
    assert session.process(frames[1].image, frames[1].stamp).ok
    assert (session.stats.frames_in, session.stats.poses_out) == (2, 1)


def test_the_same_intrinsics_keep_the_tracker_and_new_ones_replace_it(session, config):
    tracker = session.tracker
    same = dataclasses.replace(config.camera_info, k=config.camera_info.k.copy())
    assert session.set_camera_info(same) is False and session.tracker is tracker
    other = config.camera_info.scaled(320, 240)
    assert session.set_camera_info(other) is True
    assert session.tracker is not tracker and session.camera_info is other
    distorted = dataclasses.replace(other, d=np.array([0.01, 0.0, 0.0, 0.0, 0.0]))
    assert session.set_camera_info(distorted) is True


def _info_cdr(info, stamp_ns, **changes):
    data = dataclasses.replace(camera_info_to_data(info), **changes)
    return serialize(convert.camera_info(stamp_ns, data))


def test_camera_info_messages_rebuild_the_tracker_only_on_new_intrinsics(config, no_calibration):
    session = TrackingSession(no_calibration)
    info = config.camera_info
    assert session.set_camera_info_message(_info_cdr(info, 1)) is True
    tracker = session.tracker
    # Beside every frame: the same intrinsics under the next stamp keep the tracker.
    assert session.set_camera_info_message(_info_cdr(info, 2)) is False
    assert session.tracker is tracker
    smaller = info.scaled(320, 240)
    assert session.set_camera_info_message(_info_cdr(smaller, 3)) is True
    assert session.camera_info.width == 320 and session.tracker is not tracker
    assert session.set_camera_info_message(_info_cdr(info, 4)) is True
    assert session.camera_info.width == info.width


def test_a_refused_camera_info_message_is_refused_again(config, no_calibration):
    session = TrackingSession(no_calibration)
    for stamp in (1, 2):  # a refusal is not remembered as taken
        uncalibrated = _info_cdr(config.camera_info, stamp, k=np.zeros((3, 3)))
        with pytest.raises(LumpbeamError, match='uncalibrated'):
            session.set_camera_info_message(uncalibrated)
        assert session.tracker is None
    good = _info_cdr(config.camera_info, 3)
    assert session.set_camera_info_message(good) is True
    with pytest.raises(BagError):
        session.set_camera_info_message(good[:40])
    tracker = session.tracker
    assert session.set_camera_info_message(good) is False and session.tracker is tracker


@pytest.mark.parametrize('model', ['curved', '', 'PLANE'])
def test_an_unknown_pose_model_is_refused(config, model):
    with pytest.raises(LumpbeamError, match=f'pose model {model!r} is not one of plane, free'):
        TrackingSession(config, config.camera_info, model)


def test_an_image_message_is_decoded_and_tracked(session, frames):
    frame = frames[2]
    stamp_ns = round(frame.stamp * 1e9)
    decoded, result = session.process_message(image_cdr(frame.image, 'mono8', stamp_ns))
    assert decoded is not None and decoded.stamp_ns == stamp_ns
    assert result.ok and abs(result.pose[1] - frame.truth[1]) < 50e-6


def test_a_compressed_message_is_decoded_and_tracked(session, frames):
    frame = frames[3]
    data = compressed_cdr(encoded(frame.image, 'PNG'), 'png', round(frame.stamp * 1e9))
    decoded, result = session.process_message(data, COMPRESSED_IMAGE_TYPE)
    assert decoded.encoding == 'mono8' and result.ok


@pytest.mark.parametrize(
    ('data', 'msgtype', 'reason'),
    [
        (b'\x00\x01\x00\x00', 'sensor_msgs/msg/Image', 'corrupt sensor_msgs/msg/Image message'),
        (b'\x00\x01\x00\x00', 'sensor_msgs/msg/PointCloud2', 'is not an image type'),
        ('float', 'sensor_msgs/msg/Image', "unsupported image encoding '32FC1'"),
    ],
    ids=['corrupt', 'not-an-image', 'float-image'],
)
def test_an_undecodable_message_is_a_lost_frame(session, data, msgtype, reason):
    if data == 'float':
        data = image_cdr(np.zeros((4, 4), np.uint8), '32FC1')
    decoded, result = session.process_message(data, msgtype)
    assert decoded is None
    assert result.status == TrackStatus.BAD_IMAGE and reason in result.reason
    assert math.isnan(result.stamp)
    stats = session.stats
    assert (stats.frames_in, stats.poses_out, stats.lost) == (1, 0, {'bad_image': 1})
    assert reason in stats.last_reason


def test_bad_pixels_are_counted_by_status(session, frames):
    image = frames[0].image
    session.process(np.zeros_like(image), 1.0)
    session.process(np.full_like(image, 255), 2.0)
    dark = session.process(np.zeros_like(image), 3.0)
    assert session.process(image, frames[0].stamp).ok
    stats = session.stats
    assert stats.lost == {'too_dark': 2, 'saturated': 1}
    assert (stats.frames_in, stats.poses_out, stats.frames_lost) == (4, 1, 3)
    assert stats.last_stamp == frames[0].stamp
    assert dark.reason and stats.last_reason == dark.reason  # kept after the next pose


def test_reject_counts_a_frame_that_never_decoded(session):
    result = session.reject('truncated PNG', 4.5)
    assert (result.status, result.reason, result.stamp) == (
        TrackStatus.BAD_IMAGE,
        'truncated PNG',
        4.5,
    )
    assert session.stats.last_stamp == 4.5 and session.stats.last_reason == 'truncated PNG'


def test_fresh_stats_are_empty():
    stats = SessionStats()
    assert (stats.frames_in, stats.poses_out, stats.frames_lost) == (0, 0, 0)
    assert math.isnan(stats.last_stamp) and stats.last_reason == '' and not stats.lost
