import subprocess
import sys

import cv2
import numpy as np
import pytest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from footage import write_calibration, write_video
from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped
from harness import SENSOR_QOS, ros_env
from rclpy.parameter import Parameter
from rclpy.qos import QoSProfile
from sensor_msgs.msg import CameraInfo as CameraInfoMsg
from sensor_msgs.msg import Image

from lumpbeam_lab.camera.accuracy import drop_test_trajectory, render_frames
from lumpbeam_ros.base.errors import ConfigError, LumpbeamError
from lumpbeam_ros.core.bagio import BagWriter, convert
from lumpbeam_ros.core.bagio.typestore import serialize
from lumpbeam_ros.core.vision.config import load_camera_config
from lumpbeam_ros.core.vision.messages import camera_info_to_data
from lumpbeam_ros.core.vision.sources import FootageError
from lumpbeam_ros.nodes.camera_node import CameraNode

WIDTH, HEIGHT = 640, 480
#: Image stamps far from zero: a float second there cannot carry every nanosecond.
EPOCH_NS = 1_732_000_000_123_456_789


@pytest.fixture(scope='module')
def frames():
    config = load_camera_config().with_resolution(WIDTH, HEIGHT)
    return render_frames(config, drop_test_trajectory().between(1.95, 2.2), 12)


@pytest.fixture(scope='module')
def info_bytes():
    info = load_camera_config().with_resolution(WIDTH, HEIGHT).camera_info
    return serialize(convert.camera_info(EPOCH_NS, camera_info_to_data(info)))


def _image_bytes(pixels, index, encoding='mono8'):
    return serialize(convert.image(EPOCH_NS + index * 5_555_556, pixels, 'camera', encoding))


class Feed:
    """Publishes serialized camera messages into the graph, one frame at a time."""

    def __init__(self, graph, node):
        self.graph, self.node = graph, node
        self.images = graph.node.create_publisher(Image, '/camera/image_raw', SENSOR_QOS)
        self.infos = graph.node.create_publisher(CameraInfoMsg, '/camera/camera_info', SENSOR_QOS)
        assert graph.spin_until(lambda: self.images.get_subscription_count() >= 1, 10.0)
        assert graph.spin_until(lambda: self.infos.get_subscription_count() >= 1, 10.0)

    def info(self, data):
        before = self.node.session.camera_info
        self.infos.publish(data)
        self.graph.spin_until(lambda: self.node.session.camera_info is not before, 1.0)

    def image(self, data):
        """Publishes until the node has taken the frame (best effort may drop one)."""
        count = self.node.session.stats.frames_in
        for _ in range(5):
            self.images.publish(data)
            if self.graph.spin_until(lambda: self.node.session.stats.frames_in > count, 2.0):
                return
        raise AssertionError('the node never received the frame')


@pytest.fixture
def node(ros_graph):
    # The tests publish diagnostics themselves; a periodic one on a slow machine would end
    # the counting period in the middle of a test.
    quiet = [Parameter('diagnostics_period_s', value=3600.0)]
    node = CameraNode(context=ros_graph.context, parameter_overrides=quiet)
    ros_graph.add_node(node)
    return node


def test_images_in_poses_out_matching_the_truth(ros_graph, node, frames, info_bytes):
    poses = ros_graph.collect('/tip_pose', PoseStamped, QoSProfile(depth=100))
    covariances = ros_graph.collect(
        '/tip_pose_covariance', PoseWithCovarianceStamped, QoSProfile(depth=100)
    )
    feed = Feed(ros_graph, node)
    feed.info(info_bytes)
    for i, frame in enumerate(frames):
        feed.image(_image_bytes(frame.image, i))
    assert ros_graph.spin_until(lambda: len(poses) == len(covariances) == len(frames), 5.0)
    for i, (pose, with_cov, frame) in enumerate(zip(poses, covariances, frames, strict=True)):
        stamp_ns = pose.header.stamp.sec * 1_000_000_000 + pose.header.stamp.nanosec
        assert stamp_ns == EPOCH_NS + i * 5_555_556
        assert pose.header.frame_id == 'beam_base'
        _, x, z, pitch, _ = convert.pose_values(pose)
        assert abs(z - frame.truth[1]) < 20e-6
        assert abs(x - frame.truth[0]) < 50e-6
        assert abs(pitch - frame.truth[2]) < 1e-4
        assert with_cov.header == pose.header and with_cov.pose.pose == pose.pose
        cov = np.reshape(with_cov.pose.covariance, (6, 6))
        assert np.all(np.diag(cov)[[0, 2, 4]] > 0) and np.diag(cov)[[1, 3, 5]].sum() == 0
        # A few micrometres of claimed standard deviation, as the fit's residuals say.
        assert 1e-7 < np.sqrt(cov[2, 2]) < 2e-5
    assert node.session.stats.frames_lost == 0
    assert node.diagnostic_status().level == DiagnosticStatus.OK


def _bad_images(pixels):
    occluded = pixels.copy()
    occluded[:, WIDTH // 2 - 40 : WIDTH // 2 + 40] = 110
    short = convert.image(EPOCH_NS, pixels, 'camera')
    short.data = short.data[:-WIDTH]  # one row missing: data size != step * height
    wrong_encoding = convert.image(EPOCH_NS, pixels, 'camera')
    wrong_encoding.encoding = '16UC1'
    return {
        # Without a track to follow, the detector finds no whole board.
        'occluded': (_image_bytes(occluded, 0), 'board_not_found'),
        'empty wall': (_image_bytes(np.full_like(pixels, 110), 0), 'too_dark'),
        'black': (_image_bytes(np.zeros_like(pixels), 0), 'too_dark'),
        'saturated': (_image_bytes(np.full_like(pixels, 255), 0), 'saturated'),
        'short data': (serialize(short), 'bad_image'),
        'wrong encoding': (serialize(wrong_encoding), 'bad_image'),
        'corrupt bytes': (b'\x00\x01\x00\x00' + bytes(range(200)), 'bad_image'),
        'wrong size': (_image_bytes(pixels[:240, :320].copy(), 0), 'bad_image'),
    }


def test_bad_frames_give_no_pose_and_a_diagnostic(ros_graph, node, frames, info_bytes):
    poses = ros_graph.collect('/tip_pose', PoseStamped, QoSProfile(depth=100))
    diagnostics = ros_graph.collect('/diagnostics', DiagnosticArray)
    feed = Feed(ros_graph, node)
    # Before any camera_info: wait, do not guess.
    feed.image(_image_bytes(frames[0].image, 0))
    assert node.session.stats.lost['no_camera_info'] == 1
    # An uncalibrated camera's info (K = 0) is refused; the node keeps waiting.
    zero_k = load_camera_config().with_resolution(WIDTH, HEIGHT).camera_info
    bad_info = convert.camera_info(EPOCH_NS, camera_info_to_data(zero_k))
    bad_info.k = np.zeros(9)
    node.on_camera_info(serialize(bad_info))
    assert node.session.camera_info is None
    feed.info(info_bytes)
    bad = _bad_images(frames[0].image)
    for name, (data, status) in bad.items():
        lost = node.session.stats.lost[status]
        feed.image(data)
        assert node.session.stats.lost[status] == lost + 1, name
    ros_graph.spin_for(0.2)
    assert poses == []
    # The stream recovers on the next good frame.
    feed.image(_image_bytes(frames[1].image, 1))
    assert ros_graph.spin_until(lambda: len(poses) == 1, 5.0)
    node.publish_diagnostics()
    assert ros_graph.spin_until(lambda: len(diagnostics) >= 1, 5.0)
    status = diagnostics[-1].status[0]
    values = {kv.key: kv.value for kv in status.values}
    assert status.name == 'lumpbeam/camera' and status.level == DiagnosticStatus.WARN
    assert values['frames_in'] == str(len(bad) + 2)
    assert values['poses_out'] == '1'
    assert values['lost_bad_image'] == '4' and values['lost_too_dark'] == '2'
    assert values['lost_board_not_found'] == '1' and values['lost_no_camera_info'] == '1'
    assert values['camera_info'] == 'received'


def test_parameters_come_from_the_camera_file_and_are_checked(ros_graph):
    node = CameraNode(
        context=ros_graph.context,
        parameter_overrides=[
            Parameter('tracker.max_rms_px', value=0.25),
            Parameter('frame_id', value='base'),
        ],
    )
    assert node.config.tracker.max_rms_px == 0.25
    assert node.config.rig.board.squares_x == 9  # the file's default
    assert node.frame_id == 'base'
    descriptor = node.describe_parameter('tracker.max_rms_px')
    assert descriptor.read_only and 'RMS reprojection error' in descriptor.description
    assert descriptor.floating_point_range[0].from_value == 0.0
    node.destroy_node()
    with pytest.raises(ConfigError, match='board.squares_y'):
        CameraNode(
            context=ros_graph.context,
            parameter_overrides=[Parameter('board.squares_y', value=9)],
        )


def _write_bag(path, frames, info_bytes, corrupt_at=None):
    with BagWriter(path) as bag:
        bag.add_topic('/camera/image_raw', 'sensor_msgs/msg/Image')
        bag.add_topic('/camera/camera_info', 'sensor_msgs/msg/CameraInfo')
        for i, frame in enumerate(frames):
            ns = EPOCH_NS + i * 5_555_556
            bag.write_raw('/camera/camera_info', ns, info_bytes)
            data = b'\x00\x01\x00\x00garbage' if i == corrupt_at else _image_bytes(frame.image, i)
            bag.write_raw('/camera/image_raw', ns, data)


def test_bag_source_survives_a_corrupt_frame(ros_graph, frames, info_bytes, tmp_path):
    _write_bag(tmp_path / 'bag', frames, info_bytes, corrupt_at=5)
    poses = ros_graph.collect('/tip_pose', PoseStamped, QoSProfile(depth=100))
    node = CameraNode(
        context=ros_graph.context,
        parameter_overrides=[Parameter('bag_path', value=str(tmp_path / 'bag'))],
    )
    ros_graph.add_node(node)
    ros_graph.spin_until(lambda: node.pose_publisher.get_subscription_count() >= 1, 5.0)
    node.run_bag()
    stats = node.session.stats
    assert (stats.frames_in, stats.poses_out) == (len(frames), len(frames) - 1)
    assert 'corrupt' in stats.last_reason
    assert ros_graph.spin_until(lambda: len(poses) == len(frames) - 1, 5.0)
    stamps = [p.header.stamp.sec * 1_000_000_000 + p.header.stamp.nanosec for p in poses]
    assert EPOCH_NS + 5 * 5_555_556 not in stamps


def test_main_reads_a_bag_with_a_params_file_and_rejects_a_missing_bag(
    ros_graph, frames, info_bytes, tmp_path
):
    """A subscriber that comes once the node is up still gets every pose of the bag.

    The node tracked a bag as fast as it could and exited: a subscriber that matched later
    than the first frame missed poses, one that matched after the last missed them all.
    """
    _write_bag(tmp_path / 'bag', frames[:6], info_bytes)
    env = ros_env(ros_graph.domain_id)
    base = [sys.executable, '-m', 'lumpbeam_ros.nodes.camera_node', '--ros-args']
    # The node's wait starts before its diagnostics reach this graph, which under load takes
    # seconds: the default 5 s could run out before the subscriber below exists. The poses
    # go to a topic of this test's own: the domain's graph may still list an earlier test's
    # /tip_pose subscriber, and the node would not wait for this one.
    topic = '/late_subscriber/tip_pose'
    params = [
        '--params-file', 'config/camera.yaml',
        '-p', 'diagnostics_period_s:=0.1', '-p', 'wait_for_subscriber_s:=60.0',
        '-r', f'/tip_pose:={topic}',
    ]  # fmt: skip
    statuses = ros_graph.collect('/diagnostics', DiagnosticArray, 10)
    process = subprocess.Popen(
        [*base, *params, '-p', f'bag_path:={tmp_path / "bag"}'],
        env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        # The node is up (its diagnostics come), and has had time for the six frames,
        # before /tip_pose has a subscriber.
        assert ros_graph.spin_until(lambda: len(statuses) > 0, 30.0)
        ros_graph.spin_for(2.0)
        poses = ros_graph.collect(topic, PoseStamped, QoSProfile(depth=100))
        stdout, stderr = process.communicate(timeout=30)
    finally:
        process.kill()
    assert process.returncode == 0, stderr
    assert '6 frames, 6 poses' in stdout
    assert ros_graph.spin_until(lambda: len(poses) == 6, 5.0), (len(poses), stderr)
    missing = subprocess.run(
        [*base, '-p', f'bag_path:={tmp_path / "nope"}'],
        env=env, capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert missing.returncode == 2
    assert missing.stderr.strip().startswith('camera_node: error:')
    assert len(missing.stderr.strip().splitlines()) == 1


# -- in-process footage: a video, an image folder, a capture device ------------------------


def _footage_node(ros_graph, **parameters):
    overrides = [Parameter(name, value=value) for name, value in parameters.items()]
    node = CameraNode(context=ros_graph.context, parameter_overrides=overrides)
    ros_graph.add_node(node)
    ros_graph.spin_until(lambda: node.pose_publisher.get_subscription_count() >= 1, 5.0)
    return node


@pytest.fixture
def calibration_url(tmp_path):
    info = load_camera_config().with_resolution(WIDTH, HEIGHT).camera_info
    return f'file://{write_calibration(tmp_path / "camera.yaml", info)}'


def test_a_video_with_a_calibration_file_in_process(ros_graph, frames, tmp_path, calibration_url):
    video = write_video(tmp_path / 'clip.mkv', [f.image for f in frames], 'FFV1')
    poses = ros_graph.collect('/tip_pose', PoseStamped, QoSProfile(depth=100))
    node = _footage_node(
        ros_graph, footage_path=str(video), footage_fps=180.0, footage_start_time_s=1.95,
        camera_info_url=calibration_url,
    )  # fmt: skip
    node.run_footage()
    assert (node.session.stats.frames_in, node.session.stats.poses_out) == (12, 12)
    assert ros_graph.spin_until(lambda: len(poses) == len(frames), 5.0)
    for i, (pose, frame) in enumerate(zip(poses, frames, strict=True)):
        stamp_ns, x, z, pitch, _ = convert.pose_values(pose)
        assert stamp_ns == 1_950_000_000 + round(i * 1e9 / 180)
        assert abs(z - frame.truth[1]) < 20e-6 and abs(pitch - frame.truth[2]) < 1e-4


def test_a_video_device_goes_through_opencv_capture(ros_graph, frames, tmp_path, calibration_url):
    """A video file given as the device takes the live path: stamped by the node's clock."""
    video = write_video(tmp_path / 'clip.avi', [f.image for f in frames], 'MJPG')
    poses = ros_graph.collect('/tip_pose', PoseStamped, QoSProfile(depth=100))
    node = _footage_node(ros_graph, video_device=str(video), camera_info_url=calibration_url)
    before = node.get_clock().now().nanoseconds
    node.run_footage()
    after = node.get_clock().now().nanoseconds
    assert node.session.stats.poses_out == len(frames)
    assert ros_graph.spin_until(lambda: len(poses) == len(frames), 5.0)
    stamps = [convert.pose_values(p)[0] for p in poses]
    assert before <= stamps[0] and stamps == sorted(stamps) and stamps[-1] <= after
    assert all(abs(convert.pose_values(p)[2] - f.truth[1]) < 30e-6 for p, f in
               zip(poses, frames, strict=True))  # fmt: skip


def test_bad_footage_frames_give_warnings_and_a_diagnostic(
    ros_graph, frames, tmp_path, calibration_url
):
    folder = tmp_path / 'frames'
    folder.mkdir()
    for i, frame in enumerate(frames[:6]):
        cv2.imwrite(str(folder / f'{i:03d}.png'), frame.image)
    (folder / '002.png').write_bytes(b'\x89PNG\r\n\x1a\n broken')  # a corrupt file
    cv2.imwrite(str(folder / '004.png'), cv2.resize(frames[4].image, (320, 240)))  # mixed sizes
    poses = ros_graph.collect('/tip_pose', PoseStamped, QoSProfile(depth=100))
    node = _footage_node(
        ros_graph, footage_path=str(folder), footage_fps=30.0, camera_info_url=calibration_url
    )
    node.run_footage()
    stats = node.session.stats
    assert (stats.frames_in, stats.poses_out, stats.lost['bad_image']) == (6, 4, 2)
    assert ros_graph.spin_until(lambda: len(poses) == 4, 5.0)
    ros_graph.spin_for(0.2)
    assert len(poses) == 4  # nothing for the two bad frames
    stamps = [convert.pose_values(p)[0] for p in poses]
    assert stamps == [round(i * 1e9 / 30) for i in (0, 1, 3, 5)]
    status = node.diagnostic_status()
    values = {kv.key: kv.value for kv in status.values}
    assert status.level == DiagnosticStatus.WARN and values['lost_bad_image'] == '2'
    # The last lost frame, 004.png, is the one of another size.
    assert 'calibrated for 640 x 480 px but the image is 320 x 240 px' in values['last_reason']


@pytest.mark.parametrize(
    ('parameters', 'error', 'match'),
    [
        ({'camera_info_url': 'file:///nonexistent/cam.yaml'}, ConfigError, 'cannot read'),
        ({'camera_info_url': 'package://x/cam.yaml'}, ConfigError, 'package://'),
        ({'footage_path': 'clip.avi'}, FootageError, 'set camera_info_url'),
    ],
)
def test_bad_calibration_or_footage_parameters_are_refused(ros_graph, parameters, error, match):
    with pytest.raises(error, match=match):
        node = _footage_node(ros_graph, **parameters)
        node.run_footage()


def test_a_calibration_with_an_unsupported_model_is_refused(ros_graph, tmp_path):
    info = load_camera_config().with_resolution(WIDTH, HEIGHT).camera_info
    path = write_calibration(tmp_path / 'fisheye.yaml', info, model='kannala_brandt_x')
    with pytest.raises(ConfigError, match='fisheye.yaml: camera info:.*kannala_brandt_x'):
        _footage_node(ros_graph, camera_info_url=f'file://{path}')


def test_main_refuses_unreadable_footage_in_one_line(ros_graph, tmp_path, calibration_url):
    (tmp_path / 'clip.avi').write_text('not a video')
    env = ros_env(ros_graph.domain_id)
    done = subprocess.run(
        [sys.executable, '-m', 'lumpbeam_ros.nodes.camera_node', '--ros-args',
         '-p', f'footage_path:={tmp_path / "clip.avi"}', '-p', 'footage_fps:=30.0',
         '-p', f'camera_info_url:={calibration_url}'],
        env=env, capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert done.returncode == 2
    err = done.stderr.strip()
    assert err.startswith('camera_node: error:') and len(err.splitlines()) == 1
    assert 'clip.avi: OpenCV cannot open it as a video' in err


def test_pose_model_parameter(ros_graph):
    node = CameraNode(
        context=ros_graph.context,
        parameter_overrides=[Parameter('pose_model', value='free')],
    )
    assert node.session.pose_model == 'free'
    node.destroy_node()
    with pytest.raises(LumpbeamError, match="pose_model: must be one of plane, free, got 'bent'"):
        CameraNode(
            context=ros_graph.context,
            parameter_overrides=[Parameter('pose_model', value='bent')],
        )


def test_a_stamp_that_goes_back_is_counted_warned_and_published(ros_graph, node):
    from lumpbeam_ros.core.vision.tracker import TrackResult, TrackStatus

    poses = ros_graph.collect('/tip_pose', PoseStamped, 10)
    result = TrackResult(
        1.0, TrackStatus.OK, pose=np.array([2.3, -0.01, 0.0]), covariance=np.eye(3) * 1e-12
    )
    for stamp_s in (10.0, 11.0, 10.0, 11.0, 11.0):  # back 1 s, on again, repeated
        node.publish_pose(int(stamp_s * 1e9), result)
    assert node.stamps_back == 2
    assert ros_graph.spin_until(lambda: len(poses) == 5, 5.0)
    assert [p.header.stamp.sec for p in poses] == [10, 11, 10, 11, 11]
    values = {kv.key: kv.value for kv in node.diagnostic_status().values}
    assert values['stamps_back'] == '2'
