"""The camera node: camera frames in, the tip pose out (doc/interfaces.md, 'Topics').

Subscribes to ``/camera/image_raw`` and ``/camera/camera_info`` (sensor-data QoS: best
effort, a late frame is worth less than the next) and publishes, stamped with each image's
own stamp:

- ``/tip_pose`` (``geometry_msgs/PoseStamped`` in ``beam_base``),
- ``/tip_pose_covariance`` (``geometry_msgs/PoseWithCovarianceStamped``, the same pose with
  the fit's covariance),
- ``/diagnostics`` at 1 Hz: status ``lumpbeam/camera`` with frames in and out, frames lost
  by reason and the last reason.

Images are taken as serialized bytes and decoded with the bag code
(:mod:`lumpbeam_ros.core.vision.messages`), so a live frame and a recorded one go through the
same lines. A frame that gives no pose (board lost, bad encoding, wrong size, black,
saturated, corrupt, no camera info yet) gives no message, a throttled warning and a count
in the diagnostics; never a stale pose, never an exception out of a callback.

Instead of subscribing, the node can read frames in-process (as fast as it tracks, for rates
a topic cannot carry): a bag with ``bag_path`` (:meth:`CameraNode.run_bag`; ``Image`` or
``CompressedImage``), a video file or an image folder with ``footage_path`` and its stamps
(``footage_fps`` or ``footage_timestamps``), or a live camera through OpenCV's capture API
with ``video_device`` (a device index such as ``0``, a device path such as ``/dev/video2``,
or any file or URL OpenCV opens; each frame is stamped with the node's clock when it
arrives) (:meth:`CameraNode.run_footage`). The readers are the ROS-free ones of
:mod:`lumpbeam_ros.core.vision.sources`, shared with ``lumpbeam track``. A bag or footage is
finite and read faster than real time, so the node first waits (``wait_for_subscriber_s``,
bounded) until ``/tip_pose`` has a subscriber, as ``lumpbeam play --delay`` does, and before
exiting until reliable subscribers have every pose: a subscriber started beside the node
still gets the whole run. It does not pace the frames at the recording's rate: the
in-process reading is there to track faster than a topic would carry the frames.

The intrinsics come from ``/camera/camera_info``, or from a ROS camera calibration file
given as ``camera_info_url`` (``file:///path/camera.yaml``, as camera_info_manager takes it),
or from the ``camera.*`` parameters with ``use_config_camera_info``.

Parameters: :data:`~lumpbeam_ros.nodes.params.camera_params.CAMERA_SCHEMA` (``doc/parameters.md``):
the keys of ``config/camera.yaml`` plus the node's own, all read-only. Run it with
``camera_node --ros-args --params-file camera.yaml``.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Callable, Sequence
from typing import Any, Unpack

import numpy as np
import rclpy
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import PoseStamped, PoseWithCovarianceStamped
from rclpy.clock import Clock, ClockType
from rclpy.duration import Duration
from sensor_msgs.msg import CameraInfo as CameraInfoMsg
from sensor_msgs.msg import Image

from lumpbeam_ros.base.errors import BagError, LumpbeamError
from lumpbeam_ros.base.interface import (
    CAMERA_INFO,
    CAMERA_NODE,
    CAMERA_STATUS,
    DIAGNOSTICS,
    IMAGE,
    IMAGE_TYPE,
    TIP_POSE,
    TIP_POSE_COVARIANCE,
)
from lumpbeam_ros.core.bagio import BagReader
from lumpbeam_ros.core.bagio.convert import NS_PER_S, pitch_to_quaternion
from lumpbeam_ros.core.vision.bag_frames import bag_frames
from lumpbeam_ros.core.vision.camera_info_file import camera_info_from_url
from lumpbeam_ros.core.vision.config import camera_config_from_parameters
from lumpbeam_ros.core.vision.free_pose import rpy_quaternion
from lumpbeam_ros.core.vision.messages import IMAGE_TYPES, prepare_decoders
from lumpbeam_ros.core.vision.session import TrackingSession
from lumpbeam_ros.core.vision.sources import (
    DeviceSource,
    FolderSource,
    FootageError,
    FrameStamps,
    VideoSource,
    open_footage,
)
from lumpbeam_ros.core.vision.tracker import TrackResult
from lumpbeam_ros.nodes.endpoints import publisher, subscription
from lumpbeam_ros.nodes.lifecycle import run_node, spin_events
from lumpbeam_ros.nodes.params.camera_params import CAMERA_SCHEMA, CONFIG_KEYS
from lumpbeam_ros.nodes.ros_parameters import NodeOptions, SchemaNode

# PoseWithCovariance is row-major 6 x 6 over (x, y, z, rot x, rot y, rot z); the tracker
# measures x, z and the rotation about y (the pitch).
_COVARIANCE_INDEX = np.array([0, 2, 4])


def _stamp(msg: Any, stamp_ns: int) -> None:
    msg.sec, msg.nanosec = divmod(int(stamp_ns), NS_PER_S)


class CameraNode(SchemaNode):
    """Tracks the tip in camera frames and publishes its pose.

    Args:
        **options: See :class:`~lumpbeam_ros.nodes.ros_parameters.NodeOptions`.

    Raises:
        ConfigError: A camera parameter is invalid.
        LumpbeamError: The configured board is not in view of the configured camera.
    """

    def __init__(self, **options: Unpack[NodeOptions]):
        super().__init__(CAMERA_SCHEMA, **options)
        values = self.parameter_values
        self.config = camera_config_from_parameters(
            {key: values[key] for key in CONFIG_KEYS}, f'{self.get_name()} parameters'
        )
        self.frame_id = str(self._param('frame_id'))
        known = self.config.camera_info if self._param('use_config_camera_info') else None
        url = str(self._param('camera_info_url'))
        if url:
            known = camera_info_from_url(url)
        self.session = TrackingSession(self.config, known, str(self._param('pose_model')))
        #: Why the in-process source stopped early (empty: it did not).
        self.source_problem = ''
        self._warning_period = float(self._param('warning_period_s'))
        self._period_counts = (0, 0)
        self._period_start = time.monotonic()
        #: Poses whose image stamp was not after the previous pose's (published all the same).
        self.stamps_back = 0
        self._last_stamp_ns: int | None = None

        # /tip_pose: reliable, more than a second of poses; images and camera info: best
        # effort, a third of a second of frames (lumpbeam_ros.core.bagio.qos).
        self.pose_publisher = publisher(self, PoseStamped, TIP_POSE)
        self.covariance_publisher = publisher(self, PoseWithCovarianceStamped, TIP_POSE_COVARIANCE)
        self.diagnostics_publisher = publisher(self, DiagnosticArray, DIAGNOSTICS)
        self.bag_path = str(self._param('bag_path'))
        self.footage_path = str(self._param('footage_path'))
        self.video_device = str(self._param('video_device'))
        if not self.in_process:
            prepare_decoders()
            # Raw: the bytes go to the same decoder as a bag's, without rclpy's copy.
            subscription(self, Image, IMAGE, self.on_image, raw=True)
            subscription(self, CameraInfoMsg, CAMERA_INFO, self.on_camera_info, raw=True)
            # Said now, not at the first frame: a node's first log line costs tens of
            # milliseconds, which the stream's first frames would wait for.
            source = 'the configured intrinsics' if known is not None else CAMERA_INFO
            self.get_logger().info(f'tracking {IMAGE} with {source}')
        period = float(self._param('diagnostics_period_s'))
        # Steady: the period's counts are timed with time.monotonic (and the node's clock may
        # be a replay's /clock).
        steady = Clock(clock_type=ClockType.STEADY_TIME)
        self.create_timer(period if period > 0 else 1.0, self.publish_diagnostics, clock=steady)

    # -- parameters -------------------------------------------------------------------------

    def _param(self, name: str) -> Any:
        return self.get_parameter(name).value

    @property
    def in_process(self) -> bool:
        """Whether frames are read in-process (a bag, footage or a device), not subscribed."""
        return bool(self.bag_path or self.footage_path or self.video_device)

    # -- input ------------------------------------------------------------------------------

    def on_camera_info(self, data: bytes) -> None:
        """Takes the camera's intrinsics (published beside every frame)."""
        try:
            changed = self.session.set_camera_info_message(data)
        except LumpbeamError as exc:
            self._took_camera_info(False, str(exc))
        else:
            self._took_camera_info(changed)

    def _took_camera_info(self, changed: bool, problem: str = '') -> None:
        if problem:
            kept = 'keeping the last one' if self.session.camera_info else 'no intrinsics yet'
            self.refuse(CAMERA_INFO, f'camera info refused ({problem})', kept)
        elif changed:
            info = self.session.camera_info
            assert info is not None  # a change sets it
            self.get_logger().info(f'camera info: {info.width} x {info.height} px')

    def on_image(self, data: bytes, msgtype: str = IMAGE_TYPE) -> None:
        """Tracks one serialized image (``Image`` or ``CompressedImage``), publishes its pose."""
        frame, result = self.session.process_message(data, msgtype)
        self._publish_or_warn(None if frame is None else frame.stamp_ns, result)

    def _publish_or_warn(self, stamp_ns: int | None, result: TrackResult) -> None:
        if stamp_ns is not None and result.ok:
            self.publish_pose(stamp_ns, result)
        else:
            self.get_logger().warning(
                f'no pose: {result.reason}', throttle_duration_sec=self._warning_period
            )

    def run_bag(self, should_stop: Callable[[], bool] = lambda: False) -> None:
        """Tracks every frame of ``bag_path`` in recording order, publishing the poses.

        A corrupt message is a lost frame, not the end of the bag. Once the bag is open, the
        first frame waits for a subscriber (:meth:`wait_for_subscriber`).

        Args:
            should_stop: Polled between frames; ``True`` ends early.

        Raises:
            BagError: Not a bag, or it lacks the image topic.
        """
        reader = BagReader(self.bag_path)
        image_topic = str(self._param('bag_image_topic'))
        info_topic = str(self._param('bag_camera_info_topic'))
        msgtype = reader.require(image_topic).msgtype
        if msgtype not in IMAGE_TYPES:
            raise BagError(f'{reader.path}: topic {image_topic} has type {msgtype}, not an image')
        self.wait_for_subscriber(should_stop)
        items = bag_frames(
            reader,
            self.session,
            image_topic,
            msgtype,
            info_topic,
            topics=[image_topic, info_topic],
            should_stop=should_stop,
        )
        for item in items:
            if item.kind == 'camera_info':
                self._took_camera_info(item.info_changed, item.problem)
            elif item.frame is None:
                self._publish_or_warn(None, self.session.reject(item.problem))
            else:
                frame = item.frame
                result = self.session.process(frame.pixels, frame.stamp, frame.encoding)
                self._publish_or_warn(frame.stamp_ns, result)

    def open_source(self) -> VideoSource | FolderSource | DeviceSource:
        """Opens ``footage_path`` with its stamps, or ``video_device``.

        Raises:
            FootageError: No intrinsics, unreadable footage or device, no or too few stamps.
        """
        if self.session.camera_info is None:
            raise FootageError(
                'footage has no camera_info: set camera_info_url (or use_config_camera_info)'
            )
        if self.video_device:
            return DeviceSource(self.video_device, lambda: self.get_clock().now().nanoseconds)
        stamps = None
        if self._param('footage_timestamps'):
            stamps = FrameStamps.from_file(str(self._param('footage_timestamps')))
        elif float(self._param('footage_fps')) > 0:
            start = float(self._param('footage_start_time_s'))
            stamps = FrameStamps.from_fps(float(self._param('footage_fps')), start)
        return open_footage(self.footage_path, stamps, 'footage_fps or footage_timestamps')

    def run_footage(self, should_stop: Callable[[], bool] = lambda: False) -> None:
        """Tracks every frame of ``footage_path`` or ``video_device``, publishing the poses.

        A frame that does not decode or has the wrong size is a lost frame (a throttled
        warning, counted in the diagnostics); stamps that run out end the reading, with a
        warning and an ERROR diagnostic.

        Args:
            should_stop: Polled between frames; ``True`` ends early.

        Raises:
            FootageError: The source cannot be opened (see :meth:`open_source`).
        """
        source = self.open_source()
        if not self.video_device:  # a live camera's frames come at its pace, not faster
            self.wait_for_subscriber(should_stop)
        try:
            for frame in source:
                if frame.pixels is None:
                    result = self.session.reject(f'{frame.label}: {frame.problem}', frame.stamp)
                else:
                    result = self.session.process(frame.pixels, frame.stamp, frame.encoding)
                self._publish_or_warn(frame.stamp_ns, result)
                if should_stop():
                    break
        except FootageError as exc:
            self.source_problem = str(exc)
            self.get_logger().warning(
                f'footage stopped: {exc}', throttle_duration_sec=self._warning_period
            )

    def wait_for_subscriber(self, should_stop: Callable[[], bool] = lambda: False) -> bool:
        """Waits until ``/tip_pose`` has a subscriber, at most ``wait_for_subscriber_s``.

        A pose published before a subscriber is matched is lost to it, and a bag is read
        through in seconds: a subscriber started with the node would miss the start or all.

        Args:
            should_stop: Polled while waiting; ``True`` ends the wait.

        Returns:
            Whether a subscriber is there (a warning says when none came).
        """
        wait_s = float(self._param('wait_for_subscriber_s'))
        deadline = time.monotonic() + wait_s
        while self.pose_publisher.get_subscription_count() == 0:
            if time.monotonic() >= deadline or should_stop():
                if wait_s > 0:
                    self.get_logger().warning(
                        f'no subscriber on {TIP_POSE} after {wait_s:g} s: tracking anyway'
                    )
                return False
            time.sleep(0.02)
        return True

    def wait_for_delivery(self) -> bool:
        """Waits until reliable subscribers acknowledged every pose (``wait_for_subscriber_s``).

        A node that exits right after its last pose can take the poses still on their way
        with it.

        Returns:
            Whether everything was acknowledged in time.
        """
        wait = Duration(seconds=float(self._param('wait_for_subscriber_s')))
        return bool(self.pose_publisher.wait_for_all_acked(wait))

    # -- output -----------------------------------------------------------------------------

    def publish_pose(self, stamp_ns: int, result: TrackResult) -> None:
        """Publishes a tracked pose and its covariance with the image's stamp.

        A stamp that is not after the previous pose's (a driver's clock stepping back, a
        looping bag) is counted (``stamps_back`` in the diagnostics) with a throttled
        warning, and the pose is still published with its image's stamp: the stamp is the
        camera's word, and the subscribers drop or reset on it (the identifier and the
        diagnosis count out-of-order poses, a jump back empties their windows).
        """
        if self._last_stamp_ns is not None and stamp_ns <= self._last_stamp_ns:
            self.stamps_back += 1
            self.get_logger().warning(
                f"image stamp {stamp_ns * 1e-9:.9f} s is not after the previous pose's "
                f'{self._last_stamp_ns * 1e-9:.9f} s ({self.stamps_back} so far)',
                throttle_duration_sec=self._warning_period,
            )
        self._last_stamp_ns = stamp_ns
        x, z, pitch = (float(v) for v in result.pose)
        msg = PoseStamped()
        _stamp(msg.header.stamp, stamp_ns)
        msg.header.frame_id = self.frame_id
        msg.pose.position.x, msg.pose.position.z = x, z
        q = msg.pose.orientation
        q.x, q.y, q.z, q.w = pitch_to_quaternion(pitch)
        if result.pose6 is not None:
            msg.pose.position.y = float(result.pose6[1])
            q.x, q.y, q.z, q.w = rpy_quaternion(*result.pose6[3:])
        self.pose_publisher.publish(msg)
        with_covariance = PoseWithCovarianceStamped(header=msg.header)
        with_covariance.pose.pose = msg.pose
        # y, roll and yaw are fixed by the planar model (zero variance): not free guesses.
        covariance = np.zeros((6, 6))
        covariance[np.ix_(_COVARIANCE_INDEX, _COVARIANCE_INDEX)] = result.covariance
        if result.covariance6 is not None:
            covariance = result.covariance6
        with_covariance.pose.covariance = covariance.ravel().tolist()
        self.covariance_publisher.publish(with_covariance)

    def diagnostic_status(self) -> DiagnosticStatus:
        """Builds the ``lumpbeam/camera`` status: counts since start and over the last period.

        Level: OK when every frame of the period gave a pose, WARN when some were lost or
        none arrived, ERROR when frames arrived and none gave a pose.
        """
        stats = self.session.stats
        now = time.monotonic()
        elapsed = max(now - self._period_start, 1e-9)
        frames = stats.frames_in - self._period_counts[0]
        poses = stats.poses_out - self._period_counts[1]
        self._period_counts = (stats.frames_in, stats.poses_out)
        self._period_start = now
        if self.source_problem:
            level, message = DiagnosticStatus.ERROR, f'footage stopped: {self.source_problem}'
        elif frames == 0:
            level, message = DiagnosticStatus.WARN, 'no images'
            if self.session.camera_info is None:
                message = 'no images, no camera_info'
        elif poses == 0:
            level, message = DiagnosticStatus.ERROR, f'no pose: {stats.last_reason}'
        elif poses < frames:
            level, message = DiagnosticStatus.WARN, f'{frames - poses} of {frames} frames lost'
        else:
            level, message = DiagnosticStatus.OK, 'tracking'
        tracker = self.session.tracker
        values = {
            'frames_in': stats.frames_in,
            'poses_out': stats.poses_out,
            'frames_lost': stats.frames_lost,
            'frames_per_s': frames / elapsed,
            'poses_per_s': poses / elapsed,
            'last_reason': stats.last_reason,
            'stamps_back': self.stamps_back,
            'camera_info': 'received' if self.session.camera_info is not None else 'waiting',
            'calibrated': bool(tracker is not None and tracker.calibration is not None),
        }
        values.update({f'lost_{k}': v for k, v in sorted(stats.lost.items())})
        return DiagnosticStatus(
            level=level,
            name=CAMERA_STATUS,
            message=message,
            hardware_id='camera',
            values=[KeyValue(key=k, value=repr(v) if isinstance(v, float) else str(v))
                    for k, v in values.items()],
        )  # fmt: skip

    def publish_diagnostics(self) -> None:
        """Publishes ``/diagnostics`` (the timer's callback)."""
        array = DiagnosticArray(status=[self.diagnostic_status()])
        array.header.stamp = self.get_clock().now().to_msg()
        self.diagnostics_publisher.publish(array)


def main(args: Sequence[str] | None = None) -> int:
    """Runs the node (``camera_node [--ros-args ...]``).

    Returns:
        0, or 2 for a configuration or bag error (one line on stderr).
    """
    return run_node(
        CAMERA_NODE,
        CameraNode,
        lambda node: {
            TIP_POSE: node.session.stats.poses_out,
            TIP_POSE_COVARIANCE: node.session.stats.poses_out,
        },
        args,
        run=_run,
        received=lambda node: {IMAGE: node.session.stats.frames_in},
    )


def _run(node: CameraNode) -> None:
    """Spins a live node; a node given a bag or footage reads it through, then says so."""
    if not node.in_process:
        node.get_logger().info('ready')
        spin_events(node)
        return

    def should_stop() -> bool:
        rclpy.spin_once(node, timeout_sec=0.0)  # timers: /diagnostics keeps coming
        return not rclpy.ok()

    if node.bag_path:
        node.run_bag(should_stop)
    else:
        node.run_footage(should_stop)
    node.wait_for_delivery()
    s = node.session.stats
    name = node.bag_path or node.footage_path or f'video device {node.video_device}'
    print(f'camera_node: {name}: {s.frames_in} frames, {s.poses_out} poses')


if __name__ == '__main__':
    sys.exit(main())
