"""``lumpbeam track`` offline: a bag's images or footage frames into poses, bad input refused.

The bags are written here frame by frame (a few rendered frames across the release, the
truth beside them), so each case holds exactly what it tests.
"""

import dataclasses
import struct

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from lumpbeam_lab.camera.accuracy import render_frames
from lumpbeam_ros.base.errors import BagError
from lumpbeam_ros.base.interface import (
    CAMERA_INFO,
    COMPRESSED_IMAGE,
    COMPRESSED_IMAGE_TYPE,
    IMAGE,
    IMAGE_TYPE,
    TIP_LOAD,
    TIP_POSE,
    TIP_POSE_TRUTH,
)
from lumpbeam_ros.core.bagio import BagReader, BagWriter, convert, read_tip_poses
from lumpbeam_ros.core.vision.messages import camera_info_to_data, decode_camera_info
from lumpbeam_ros.core.vision.offline import TrackSummary, pose_message, track_bag, track_footage
from lumpbeam_ros.core.vision.sources import FootageError, FootageFrame
from lumpbeam_ros.core.vision.tracker import TrackResult, TrackStatus
from lumpbeam_ros.core.viz.marker_messages import marker_array, read_marker_arrays
from lumpbeam_ros.core.viz.markers import MARKERS_TOPIC, MarkerSpec, Shape

from .helpers import compressed_cdr, encoded

#: A custom type the typestore does not know, stored with its definition.
CUSTOM = 'my_pkg/msg/Reading'
READING = b'\x00\x01\x00\x00' + struct.pack('<d', 1.5)
CORRUPT = b'\x00\x01\x00\x00\xff'


@pytest.fixture(scope='module')
def frames(config, drop_test):
    """Eight 640 x 480 frames at 180 Hz across the release."""
    return render_frames(config, drop_test.between(1.98, 2.1), 8)


def _write_bag(
    path, frames, config, *, topic=IMAGE, info=True, extras=True, corrupt=(), bad_info_at=None
):
    """A camera bag: the calibration, the images and the truth.

    ``corrupt``: frames written as bad bytes; ``extras``: also an old ``/tip_pose``,
    ``/tip_load``, a custom type and an old ``/beam_markers``; ``bad_info_at``: a K = 0
    calibration before that frame.
    """
    first = frames[0].stamp
    calibration = camera_info_to_data(config.camera_info)
    with BagWriter(path) as bag:
        bag.add_topic(topic, COMPRESSED_IMAGE_TYPE if topic == COMPRESSED_IMAGE else IMAGE_TYPE)
        if extras:
            bag.add_topic(
                '/reading', CUSTOM, msgdef='float64 value', type_hash='RIHS01_' + '0' * 64
            )
            bag.write_float(TIP_LOAD, first - 0.01, 4.5)
            bag.write_raw('/reading', convert.seconds_to_ns(first - 0.01), READING)
            old = marker_array([MarkerSpec('old', 0, Shape.SPHERE)], 0)
            bag.write_message(MARKERS_TOPIC, old, convert.seconds_to_ns(first - 0.01))
        if info:
            bag.write_camera_info(CAMERA_INFO, first - 0.005, calibration)
        for i, f in enumerate(frames):
            ns = convert.seconds_to_ns(f.stamp)
            if i == bad_info_at:
                zero = dataclasses.replace(calibration, k=np.zeros((3, 3)))
                bag.write_camera_info(CAMERA_INFO, f.stamp - 1e-4, zero)
            if i in corrupt:
                bag.write_raw(topic, ns, CORRUPT)
            elif topic == COMPRESSED_IMAGE:
                bag.write_raw(topic, ns, compressed_cdr(encoded(f.image, 'PNG'), 'png', ns))
            else:
                bag.write_image(topic, f.stamp, f.image)
            bag.write_pose(TIP_POSE_TRUTH, f.stamp, *f.truth)
            if extras:
                bag.write_pose(TIP_POSE, f.stamp, f.truth[0], f.truth[1] + 1e-3, f.truth[2])
    return path


@pytest.fixture(scope='module')
def bag(frames, config, tmp_path_factory):
    return _write_bag(tmp_path_factory.mktemp('offline') / 'camera', frames, config)


@pytest.fixture(scope='module')
def tracked(bag, no_calibration, tmp_path_factory):
    out = tmp_path_factory.mktemp('tracked') / 'out'
    calls = []
    summary = track_bag(
        bag, out, no_calibration, progress=lambda *a: calls.append(a), keep_images=True
    )
    return out, summary, calls


def test_the_images_are_left_out_unless_kept(bag, no_calibration, tmp_path):
    summary = track_bag(bag, tmp_path / 'out', no_calibration)
    assert summary.images_left_out == [IMAGE] and summary.poses == 8
    copy = BagReader(tmp_path / 'out')
    assert IMAGE not in copy.topics and {CAMERA_INFO, TIP_LOAD, '/reading'} <= set(copy.topics)
    images = [r.log_time_ns for r in BagReader(bag).iter_raw([IMAGE])]
    assert [r.log_time_ns for r in copy.iter_raw([TIP_POSE])] == images


def test_poses_far_from_the_truth_are_refused(bag, no_calibration, tmp_path):
    """The camera file of another rig: the board placed 50 mm higher than filmed."""
    rig = no_calibration.rig
    board = dataclasses.replace(
        rig.base_board, translation=rig.base_board.translation + np.array([0.0, 0.0, 0.05])
    )
    other = dataclasses.replace(no_calibration, rig=dataclasses.replace(rig, base_board=board))
    with pytest.raises(FootageError, match=r'50\.0 mm \(z RMS\) from /tip_pose_truth') as info:
        track_bag(bag, tmp_path / 'out', other)
    assert '\n' not in str(info.value)
    assert not (tmp_path / 'out').exists()


def test_every_frame_gives_a_pose_on_the_truth(tracked):
    out, summary, _ = tracked
    assert (summary.frames, summary.poses, summary.lost, summary.lost_by_reason) == (8, 8, 0, {})
    assert summary.image_topic == IMAGE and summary.first_problems == {}
    assert summary.compared == 8 and 0.0 < summary.z_rms_um < 50.0
    assert abs(summary.z_bias_um) <= summary.z_rms_um and summary.pitch_rms_mrad < 1.0
    poses, truth = read_tip_poses(out), read_tip_poses(out, TIP_POSE_TRUTH)
    np.testing.assert_array_equal(poses.t, truth.t)  # each pose carries its image's stamp
    assert np.sqrt(np.mean((poses.z - truth.z) ** 2)) * 1e6 == pytest.approx(summary.z_rms_um)


def test_the_bags_own_poses_are_replaced(tracked):
    out, summary, _ = tracked
    assert summary.replaced_poses == 8
    poses, truth = read_tip_poses(out), read_tip_poses(out, TIP_POSE_TRUTH)
    assert np.max(np.abs(poses.z - truth.z)) < 2e-4  # not the old ones, 1 mm off
    assert poses.frame_id == 'beam_base'


def test_each_pose_follows_its_image_at_its_log_time(tracked):
    out, _, _ = tracked
    raws = [r for r in BagReader(out).iter_raw([IMAGE, TIP_POSE])]
    assert [r.topic for r in raws] == [IMAGE, TIP_POSE] * 8
    for image, pose in zip(raws[::2], raws[1::2], strict=True):
        assert pose.log_time_ns == image.log_time_ns


def test_every_other_topic_is_copied_byte_for_byte(bag, tracked):
    out, summary, _ = tracked
    original, copy = BagReader(bag), BagReader(out)
    assert set(copy.topics) == set(original.topics) and summary.skipped_topics == []
    for topic in (IMAGE, CAMERA_INFO, TIP_LOAD, TIP_POSE_TRUTH, '/reading'):
        assert copy.topics[topic].msgtype == original.topics[topic].msgtype
        assert copy.topics[topic].qos == original.topics[topic].qos
        before = [(r.log_time_ns, bytes(r.data)) for r in original.iter_raw([topic])]
        assert [(r.log_time_ns, bytes(r.data)) for r in copy.iter_raw([topic])] == before


def test_the_markers_are_drawn_anew_at_30_hz(tracked):
    out, _, _ = tracked
    arrays = list(read_marker_arrays(out))
    # 8 frames at 180 Hz span 39 ms: a new array at the first and 1/30 s later (the 7th).
    assert len(arrays) == 2
    stamps = read_tip_poses(out).t
    assert [t for t, _ in arrays] == pytest.approx([stamps[0], stamps[6]], abs=1e-9)
    for _, markers in arrays:
        assert {m.namespace for m in markers} == {'tip_measured', 'load', 'board'}


def test_progress_is_called_after_each_image(tracked):
    _, _, calls = tracked
    assert calls == [(i, 8) for i in range(1, 9)]


def test_the_free_model_writes_full_poses(bag, no_calibration, tmp_path):
    summary = track_bag(bag, tmp_path / 'free', no_calibration, pose_model='free')
    assert summary.poses == 8
    ys = [
        m.pose.position.y
        for _, m in BagReader(tmp_path / 'free').messages(
            TIP_POSE, 'geometry_msgs/msg/PoseStamped'
        )
    ]
    assert np.max(np.abs(ys)) > 0.0  # 6 DoF: y is estimated, not pinned to the plane


def test_a_corrupt_image_is_a_lost_frame_named_once(frames, config, no_calibration, tmp_path):
    bag = _write_bag(tmp_path / 'bag', frames, config, extras=False, corrupt=(2, 5))
    summary = track_bag(bag, tmp_path / 'out', no_calibration)
    assert (summary.frames, summary.poses, summary.lost_by_reason) == (8, 6, {'bad_image': 2})
    assert summary.first_problems['bad_image'].startswith(f'{bag} {IMAGE} message 2: corrupt')
    assert summary.replaced_poses == 0 and summary.compared == 6


def test_compressed_images_are_tracked(frames, config, no_calibration, tmp_path):
    bag = _write_bag(tmp_path / 'bag', frames, config, topic=COMPRESSED_IMAGE, extras=False)
    summary = track_bag(bag, tmp_path / 'out', no_calibration)
    assert summary.image_topic == COMPRESSED_IMAGE and summary.poses == 8


def test_a_bad_calibration_message_keeps_the_one_in_use(frames, config, no_calibration, tmp_path):
    bag = _write_bag(tmp_path / 'bag', frames, config, extras=False, bad_info_at=4)
    assert track_bag(bag, tmp_path / 'out', no_calibration).poses == 8


def test_given_intrinsics_replace_a_missing_calibration(frames, config, no_calibration, tmp_path):
    bag = _write_bag(tmp_path / 'bag', frames[:3], config, info=False, extras=False)
    summary = track_bag(
        bag,
        tmp_path / 'out',
        no_calibration,
        camera_info=config.camera_info,
        camera_info_source='camera.yaml',
    )
    assert summary.poses == 3


def test_an_image_of_another_size_stops_the_run_and_removes_out(frames, config, tmp_path):
    bag = _write_bag(tmp_path / 'bag', frames[:2], config, extras=False)
    small = config.camera_info.scaled(320, 240)
    with pytest.raises(FootageError, match='image is 640 x 480 px but the camera info') as info:
        track_bag(
            bag, tmp_path / 'out', config, camera_info=small, camera_info_source='small.yaml'
        )
    assert '(small.yaml) is 320 x 240 px' in str(info.value)
    assert not (tmp_path / 'out').exists()


def _bag_with(path, write):
    with BagWriter(path) as bag:
        write(bag)
    return path


@pytest.mark.parametrize(
    ('case', 'match'),
    [
        ('out-exists', 'exists already; a bag is never overwritten'),
        ('no-images', 'no topic /camera/image_raw \\(image topics: none'),
        ('two-image-topics', 'image topics: /a, /b; choose one with --image-topic'),
        ('no-camera-info', 'no topic /camera/camera_info'),
        ('uncalibrated', 'camera_info: camera info: K must be'),
        ('empty-image-topic', 'has no images'),
    ],
)
def test_bad_bags_are_one_clear_error(frames, config, tmp_path, case, match):
    image = frames[0].image
    out = tmp_path / 'out'
    calibration = camera_info_to_data(config.camera_info)
    if case == 'out-exists':
        bag = _write_bag(tmp_path / 'bag', frames[:1], config, extras=False)
        out.mkdir()
    elif case == 'no-images':
        bag = _bag_with(tmp_path / 'bag', lambda b: b.write_pose(TIP_POSE, 1.0, 2.3, 0.0, 0.0))
    elif case == 'two-image-topics':

        def write(b):
            b.write_image('/a', 1.0, image)
            b.write_image('/b', 1.0, image)

        bag = _bag_with(tmp_path / 'bag', write)
    elif case == 'no-camera-info':
        bag = _bag_with(tmp_path / 'bag', lambda b: b.write_image(IMAGE, 1.0, image))
    elif case == 'uncalibrated':

        def write(b):
            b.write_camera_info(
                CAMERA_INFO, 0.5, dataclasses.replace(calibration, k=np.zeros((3, 3)))
            )
            b.write_image(IMAGE, 1.0, image)

        bag = _bag_with(tmp_path / 'bag', write)
    else:

        def write(b):
            b.add_topic(IMAGE, IMAGE_TYPE)
            b.write_camera_info(CAMERA_INFO, 0.5, calibration)

        bag = _bag_with(tmp_path / 'bag', write)
    with pytest.raises(BagError, match=match) as info:
        track_bag(bag, out, config)
    assert '\n' not in str(info.value)
    assert case == 'out-exists' or not out.exists()


@pytest.mark.parametrize(
    ('topic', 'match'),
    [
        ('/tip_pose_truth', 'has type geometry_msgs/msg/PoseStamped, not an image'),
        ('/nope', '/nope'),
    ],
    ids=['not-an-image', 'missing'],
)
def test_a_bad_image_topic_is_refused(bag, config, tmp_path, topic, match):
    with pytest.raises(BagError, match=match):
        track_bag(bag, tmp_path / 'out', config, image_topic=topic)


def test_the_only_image_topic_is_found_by_itself(frames, config, no_calibration, tmp_path):
    bag = _write_bag(tmp_path / 'bag', frames[:2], config, topic='/left/image', extras=False)
    summary = track_bag(bag, tmp_path / 'out', no_calibration)
    assert summary.image_topic == '/left/image' and summary.poses == 2


def _footage(frames, undecodable=()):
    return [
        FootageFrame(
            i,
            convert.seconds_to_ns(f.stamp),
            f'clip.avi frame {i}',
            None if i in undecodable else f.image,
            problem='truncated frame' if i in undecodable else '',
        )
        for i, f in enumerate(frames)
    ]


def test_footage_gives_poses_and_its_calibration(frames, config, no_calibration, tmp_path):
    calls = []
    summary = track_footage(
        _footage(frames, undecodable={3}),
        tmp_path / 'out',
        no_calibration,
        config.camera_info,
        'clip.avi',
        'camera.yaml',
        total=8,
        progress=lambda *a: calls.append(a),
    )
    assert (summary.frames, summary.poses, summary.lost_by_reason) == (8, 7, {'bad_image': 1})
    assert summary.first_problems == {'bad_image': 'clip.avi frame 3: truncated frame'}
    assert calls == [(i, 8) for i in range(1, 9)]
    reader = BagReader(tmp_path / 'out')
    assert set(reader.topics) == {TIP_POSE, CAMERA_INFO, MARKERS_TOPIC}
    (raw,) = reader.iter_raw([CAMERA_INFO])
    assert raw.log_time_ns == convert.seconds_to_ns(frames[0].stamp)
    info = decode_camera_info(raw.data)
    np.testing.assert_array_equal(info.k, config.camera_info.k)
    poses = read_tip_poses(tmp_path / 'out')
    expected = [f.stamp for i, f in enumerate(frames) if i != 3]
    assert poses.t == pytest.approx(expected, abs=1e-9)
    truth_z = np.array([f.truth[1] for i, f in enumerate(frames) if i != 3])
    assert np.max(np.abs(poses.z - truth_z)) < 2e-4


def test_no_footage_at_all_is_an_error_and_leaves_nothing(config, tmp_path):
    with pytest.raises(FootageError, match='clip.avi: no frames at all'):
        track_footage([], tmp_path / 'out', config, config.camera_info, 'clip.avi', 'cfg')
    assert not (tmp_path / 'out').exists()


def test_footage_of_another_size_stops(frames, config, tmp_path):
    small = config.camera_info.scaled(320, 240)
    with pytest.raises(FootageError, match='clip.avi frame 0: image is 640 x 480 px'):
        track_footage(_footage(frames[:2]), tmp_path / 'out', config, small, 'clip.avi', 'cfg')
    assert not (tmp_path / 'out').exists()


def test_footage_never_overwrites(frames, config, tmp_path):
    (tmp_path / 'out').mkdir()
    with pytest.raises(BagError, match='exists already'):
        track_footage(_footage(frames[:1]), tmp_path / 'out', config, config.camera_info, 'c', 'c')


@pytest.mark.parametrize('pitch', [0.0, 0.031, -0.2])
def test_a_planar_pose_message_turns_about_y(pitch):
    result = TrackResult(2.0, TrackStatus.OK, '', pose=np.array([2.3, -0.05, pitch]))
    message = pose_message(7, result)
    p, q = message.pose.position, message.pose.orientation
    assert (p.x, p.y, p.z) == (2.3, 0.0, -0.05) and message.header.frame_id == 'beam_base'
    yaw, turn, roll = Rotation.from_quat([q.x, q.y, q.z, q.w]).as_euler('ZYX')
    assert turn == pytest.approx(pitch, abs=1e-12) and yaw == roll == pytest.approx(0.0)


@pytest.mark.parametrize(
    'pose6',
    [[2.3, 0.01, -0.05, 0.0, 0.03, 0.0], [2.2, -0.02, 0.01, 0.1, -0.2, 0.3]],
    ids=['pitch-only', 'all-axes'],
)
def test_a_full_pose_message_keeps_every_axis(pose6):
    result = TrackResult(
        2.0, TrackStatus.OK, '', pose=np.array(pose6)[[0, 2, 4]], pose6=np.array(pose6)
    )
    message = pose_message(7, result)
    p, q = message.pose.position, message.pose.orientation
    assert (p.x, p.y, p.z) == tuple(pose6[:3])
    expected = Rotation.from_euler('ZYX', [pose6[5], pose6[4], pose6[3]])
    assert Rotation.from_quat([q.x, q.y, q.z, q.w]).approx_equal(expected, atol=1e-12)


def test_a_summary_counts_its_lost_frames():
    assert TrackSummary(frames=10, poses=7).lost == 3
    assert np.isnan(TrackSummary().z_rms_um) and TrackSummary().image_topic == ''
