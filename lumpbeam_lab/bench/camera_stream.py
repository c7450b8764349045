"""End to end through ROS topics: a camera publisher process, the camera node in another.

The publisher offers ``/camera/image_raw`` (mono8) and ``/camera/camera_info`` at a fixed
rate, stamped with the wall clock at publication; the bench process subscribes to
``/tip_pose`` and takes, per pose, receive time minus image stamp (same machine, same
clock) as the latency. The baseline is an echo node in the same position: it decodes each
image and publishes a pose with its stamp, without tracking, so the ratio shows what the
tracking costs on top of the transport.

Fast DDS's default shared-memory segment (512 kB) is smaller than a 1 MB frame, and the UDP
fallback drops most of a 180 fps stream of them; :data:`LARGE_FRAMES_PROFILE` gives the
processes a 32 MB segment. The bench runs both transports and reports both.

Run as ``python -m lumpbeam_lab.bench.camera_stream publish|echo ...`` for the processes.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from lumpbeam_ros.base.interface import (
    BASE_FRAME,
    BEAM_PARAMS,
    CAMERA_FRAME,
    CAMERA_INFO,
    IMAGE,
    TIP_POSE,
)
from lumpbeam_ros.base.resources import large_frames_profile
from lumpbeam_ros.nodes.realtime import set_normal_scheduling, set_realtime_priority
from lumpbeam_ros.nodes.ros_domain import claim_domain_id

#: Longest wait for the consumer processes to start and be discovered, s (a node importing
#: OpenCV and scipy on a busy machine takes a while).
STARTUP_TIMEOUT_S = 60.0


@dataclass(frozen=True)
class StreamFigures:
    """One run: what was offered and what came back.

    Attributes:
        published: Images published.
        received: Poses received.
        duration_s: Publishing time, s.
        latency_ms: Per received pose, receive time minus image stamp, ms.
        params_latency_ms: Per ``/beam_params`` message with a newer frame than the message
            before it (when an identifier node runs), its publication stamp minus the stamp
            of the newest frame in its window (``window_end_s``), ms.
        params_repeated: ``/beam_params`` messages whose window had no newer frame: their
            age measures a pause in the poses (the stream's end, a stalled camera), not the
            chain, so they are counted here and not timed.
    """

    published: int
    received: int
    duration_s: float
    latency_ms: np.ndarray
    params_latency_ms: np.ndarray = field(default_factory=lambda: np.empty(0))
    params_repeated: int = 0

    def percentile_ms(self, q: float) -> float:
        """A latency percentile, ms (NaN without poses)."""
        return float(np.percentile(self.latency_ms, q)) if self.latency_ms.size else float('nan')


#: Fast DDS profile: shared memory with a 32 MB segment, UDP beside it.
LARGE_FRAMES_PROFILE = large_frames_profile()


def _env(domain_id: int, large_frames: bool) -> dict[str, str]:
    env = dict(os.environ)
    env.pop('FASTRTPS_DEFAULT_PROFILES_FILE', None)
    if large_frames:
        env['FASTRTPS_DEFAULT_PROFILES_FILE'] = str(LARGE_FRAMES_PROFILE)
    root = Path.cwd() / '.cache' / 'ros'
    env.update(
        ROS_DOMAIN_ID=str(domain_id),
        ROS_AUTOMATIC_DISCOVERY_RANGE='LOCALHOST',
        ROS_LOG_DIR=str(root / 'log'),
        ROS_HOME=str(root),
    )
    return env


#: Seconds of the drop test before the release that the stream starts with.
BEFORE_RELEASE_S = 1.0


def drop_test_frames(width: int, height: int, rate_hz: float, duration_s: float) -> np.ndarray:
    """The model's drop test as the camera films it, from shortly before the release.

    What the live graph is for: a beam hanging at rest, released, ringing down. The frames
    are rendered without sensor noise, supersampling or motion blur: the benchmark times the
    tracker's work, not its accuracy (``lumpbeam bench --only tracker``), and the clean
    render is four times cheaper (some 13 s for 10 s of 1024 x 1024 frames).

    Args:
        width: Image width, px.
        height: Image height, px.
        rate_hz: Frame rate, Hz.
        duration_s: Length, s (at most the drop test's record after the stream's start).

    Returns:
        The mono8 frames (N x height x width).
    """
    from dataclasses import replace

    from lumpbeam_lab.camera.accuracy import drop_test_trajectory, render_frames
    from lumpbeam_ros.core.model.parameters import load_beam_config
    from lumpbeam_ros.core.vision.config import load_camera_config

    start = load_beam_config()[1].release_time_s - BEFORE_RELEASE_S
    trajectory = drop_test_trajectory(rate_hz).between(start, start + duration_s - 0.5 / rate_hz)
    config = load_camera_config().with_resolution(width, height)
    clean = replace(config.synthetic, noise_sigma_dn=0.0, supersample=1, max_motion_samples=1)
    frames = render_frames(replace(config, synthetic=clean), trajectory)
    return np.stack([f.image for f in frames])


def publish(frames_path: str, rate_hz: float, realtime_priority: int = 0) -> int:
    """The publisher process: offers the frames at ``rate_hz`` and prints what it published.

    Args:
        frames_path: A ``.npy`` file of mono8 frames (N x height x width).
        rate_hz: Offered frame rate, Hz.
        realtime_priority: As a camera driver's on a shared machine (0: normal).

    Returns:
        0.
    """
    import rclpy
    from sensor_msgs.msg import CameraInfo, Image

    from lumpbeam_ros.core.bagio import convert
    from lumpbeam_ros.core.bagio.typestore import serialize
    from lumpbeam_ros.core.vision.config import load_camera_config
    from lumpbeam_ros.core.vision.messages import camera_info_to_data
    from lumpbeam_ros.nodes.endpoints import publisher

    frames = np.load(frames_path, mmap_mode='r')
    count, height, width = frames.shape
    # Serialized once; only the stamp (bytes 4..12, after the CDR header) changes.
    messages = [
        bytearray(serialize(convert.image(0, np.asarray(im), CAMERA_FRAME))) for im in frames
    ]
    info = load_camera_config().with_resolution(width, height).camera_info
    info_message = bytearray(serialize(convert.camera_info(0, camera_info_to_data(info))))
    rclpy.init()
    node = rclpy.create_node('bench_camera')
    problem = set_realtime_priority(realtime_priority)
    if problem:
        node.get_logger().warning(problem)
    images = publisher(node, Image, IMAGE)
    infos = publisher(node, CameraInfo, CAMERA_INFO)
    deadline = time.monotonic() + 20.0
    # Both: a frame that comes before the camera node has matched the intrinsics is lost.
    while (
        min(images.get_subscription_count(), infos.get_subscription_count()) < 1
        and time.monotonic() < deadline
    ):
        time.sleep(0.05)
    time.sleep(0.5)  # let the subscriber's side of discovery settle too
    period = 1.0 / rate_hz
    start = time.perf_counter()
    for i in range(count):
        delay = start + i * period - time.perf_counter()
        if delay > 0:
            time.sleep(delay)
        sec, nanosec = divmod(time.time_ns(), 1_000_000_000)
        stamp = int(sec).to_bytes(4, 'little') + int(nanosec).to_bytes(4, 'little')
        message = messages[i]
        message[4:12] = stamp
        info_message[4:12] = stamp
        infos.publish(bytes(info_message))
        images.publish(bytes(message))
    elapsed = time.perf_counter() - start
    last_stamp_ns = sec * 1_000_000_000 + nanosec if count else 0
    summary = {'published': count, 'duration_s': elapsed, 'last_stamp_ns': last_stamp_ns}
    print(json.dumps(summary), flush=True)
    node.destroy_node()
    rclpy.shutdown()
    return 0


def echo(realtime_priority: int = 0) -> int:
    """The baseline process: decode each image, publish a pose with its stamp, no tracking.

    Args:
        realtime_priority: As the camera node's ``realtime_priority`` (0: normal).
    """
    import rclpy
    from geometry_msgs.msg import PoseStamped
    from sensor_msgs.msg import Image

    from lumpbeam_ros.core.vision.messages import decode_image, prepare_decoders
    from lumpbeam_ros.nodes.endpoints import publisher, subscription

    prepare_decoders()  # as the camera node does: the baseline's first frame is no slower
    rclpy.init()
    node = rclpy.create_node('bench_echo')
    problem = set_realtime_priority(realtime_priority)
    if problem:
        node.get_logger().warning(problem)
    poses = publisher(node, PoseStamped, TIP_POSE)

    def on_image(data: bytes) -> None:
        frame = decode_image(data)
        msg = PoseStamped()
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(frame.stamp_ns, 1_000_000_000)
        msg.header.frame_id = BASE_FRAME
        poses.publish(msg)

    subscription(node, Image, IMAGE, on_image, raw=True)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, rclpy.executors.ExternalShutdownException):
        pass
    return 0


class ParamsAges:
    """The age of each ``/beam_params`` message that brings a newer frame than the last.

    The identifier publishes on a timer, so while no pose comes in (the stream has ended, the
    camera stalled) it repeats the same window, and that message's age grows with the pause,
    not with the chain's latency: such messages are counted, not timed. So is the first
    message whose window ends with the stream's last frame: it waits for the timer's next
    tick (up to a period) with no newer frame to bring, its age is the timer's phase.

    Attributes:
        latencies_ms: Per timed message, its publication stamp minus the stamp of the newest
            frame in its window, ms.
        repeated: Messages whose newest frame was not newer than the last timed one's.
    """

    def __init__(self) -> None:
        self.latencies_ms: list[float] = []
        self.repeated = 0
        self._newest_s = -math.inf
        self._window_ends_s: list[float] = []

    def end_of_stream(self, last_frame_s: float) -> None:
        """Counts the messages whose newest frame is the stream's last as repeated, not timed.

        Args:
            last_frame_s: The stamp of the last frame published, s.
        """
        # Stamps travel as nanoseconds: a microsecond covers the float round trip.
        keep = [end < last_frame_s - 1e-6 for end in self._window_ends_s]
        self.repeated += keep.count(False)
        self.latencies_ms = [v for v, k in zip(self.latencies_ms, keep, strict=True) if k]
        self._window_ends_s = [e for e, k in zip(self._window_ends_s, keep, strict=True) if k]

    def add(self, published_ns: int, window_end_s: float) -> None:
        """Takes one message.

        Args:
            published_ns: Its header stamp, ns.
            window_end_s: The stamp of the newest frame in its window (``window_end_s``), s;
                a message without one (NaN: no window yet) is ignored.
        """
        if not math.isfinite(window_end_s):
            return
        if window_end_s <= self._newest_s:
            self.repeated += 1
            return
        self._newest_s = window_end_s
        self._window_ends_s.append(window_end_s)
        self.latencies_ms.append(published_ns * 1e-6 - window_end_s * 1e3)


def measure(
    consumer: Sequence[str],
    frames: np.ndarray,
    rate_hz: float,
    large_frames: bool = True,
    downstream: Sequence[str] = (),
    sink_priority: int = 0,
    publisher_priority: int = 0,
) -> StreamFigures:
    """Runs a consumer process (the camera node or the echo) against the publisher process.

    Args:
        consumer: The consumer's command line.
        frames: The mono8 frames to offer (N x height x width), e.g.
            :func:`drop_test_frames`.
        rate_hz: Offered frame rate, Hz.
        large_frames: Give the publisher and the consumer :data:`LARGE_FRAMES_PROFILE`.
        downstream: A process fed by the consumer that publishes ``/beam_params`` (the
            identifier node); empty for none.
        sink_priority: Real-time priority of this process's threads while the frames flow
            (0: the normal scheduler), set once every other process has started (they do
            not inherit it): the sink must not be the one other work delays.
        publisher_priority: The publisher's real-time priority, as a camera driver's
            (0: the normal scheduler).

    Returns:
        The figures.

    Raises:
        RuntimeError: A process failed or discovery never completed.
    """
    import rclpy
    from diagnostic_msgs.msg import DiagnosticArray
    from geometry_msgs.msg import PoseStamped
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor

    from lumpbeam_ros.nodes.endpoints import subscription

    claim = claim_domain_id()  # held until every process of the run is gone
    domain = claim.domain_id
    env = _env(domain, large_frames)
    context = Context()
    rclpy.init(context=context, domain_id=domain)
    node = rclpy.create_node('bench_sink', context=context)
    latencies: list[float] = []

    def on_pose(msg: PoseStamped) -> None:
        stamp_ns = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
        latencies.append((time.time_ns() - stamp_ns) * 1e-6)

    params = ParamsAges()

    def on_params(msg: DiagnosticArray) -> None:
        published_ns = msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec
        for status in msg.status:
            values = {kv.key: kv.value for kv in status.values}
            try:
                params.add(published_ns, float(values['window_end_s']))
            except (KeyError, ValueError):
                continue

    subscription(node, PoseStamped, TIP_POSE, on_pose)
    subscription(node, DiagnosticArray, BEAM_PARAMS, on_params)
    executor = SingleThreadedExecutor(context=context)
    executor.add_node(node)
    stop = threading.Event()

    def spin() -> None:
        while not stop.is_set():
            executor.spin_once(timeout_sec=0.05)

    spinner = threading.Thread(target=spin, daemon=True)
    spinner.start()
    processes = []
    folder = tempfile.TemporaryDirectory(prefix='camera_stream_')
    frames_path = str(Path(folder.name) / 'frames.npy')
    np.save(frames_path, frames)
    duration_s = len(frames) / rate_hz
    try:
        processes.append(subprocess.Popen(consumer, env=env, stdout=subprocess.DEVNULL))
        if downstream:
            processes.append(subprocess.Popen(downstream, env=env, stdout=subprocess.DEVNULL))
        deadline = time.monotonic() + STARTUP_TIMEOUT_S
        wanted = [TIP_POSE, BEAM_PARAMS] if downstream else [TIP_POSE]
        while unheard := [t for t in wanted if node.count_publishers(t) < 1]:
            if time.monotonic() > deadline or any(p.poll() is not None for p in processes):
                raise RuntimeError(f'no publisher of {", ".join(unheard)} appeared')
            time.sleep(0.05)
        args = ['publish', frames_path, str(rate_hz), '--realtime-priority']
        args.append(str(publisher_priority))
        publisher = subprocess.Popen(
            [sys.executable, '-m', __name__, *args], env=env, stdout=subprocess.PIPE, text=True
        )
        processes.append(publisher)
        problem = set_realtime_priority(sink_priority)
        if problem:
            print(f'camera_stream: {problem}', file=sys.stderr)
        out, _ = publisher.communicate(timeout=duration_s + 60.0)
        if publisher.returncode != 0:
            raise RuntimeError(f'publisher exited with {publisher.returncode}')
        result = json.loads(out.strip().splitlines()[-1])
        time.sleep(0.5)  # the last frames in flight
    finally:
        if sink_priority:
            set_normal_scheduling()
        for process in processes:
            if process.poll() is None:
                process.terminate()
                try:
                    process.wait(timeout=10.0)
                except subprocess.TimeoutExpired:
                    process.kill()
        stop.set()
        spinner.join(timeout=5.0)
        executor.shutdown()
        node.destroy_node()
        rclpy.shutdown(context=context)
        claim.release()
        folder.cleanup()
    params.end_of_stream(int(result['last_stamp_ns']) * 1e-9)  # the sink has stopped
    return StreamFigures(
        int(result['published']),
        len(latencies),
        float(result['duration_s']),
        np.array(latencies),
        np.array(params.latencies_ms),
        params.repeated,
    )


def camera_node_command(realtime_priority: int = 0) -> list[str]:
    """The camera node as a process, taking its intrinsics from the stream."""
    return [
        sys.executable,
        '-m',
        'lumpbeam_ros.nodes.camera_node',
        '--ros-args',
        '-p',
        f'realtime_priority:={realtime_priority}',
    ]


def identifier_command(publish_rate_hz: float, realtime_priority: int = 0) -> list[str]:
    """The identifier node as a process, on wall time, publishing at ``publish_rate_hz``."""
    from lumpbeam_ros.apps.demo.graph import node_command

    return node_command(
        'lumpbeam_ros.nodes.identifier_node',
        '-p',
        f'publish_rate_hz:={publish_rate_hz}',
        '-p',
        f'realtime_priority:={realtime_priority}',
    )


def echo_command(realtime_priority: int = 0) -> list[str]:
    """The echo baseline as a process."""
    return [sys.executable, '-m', __name__, 'echo', '--realtime-priority', str(realtime_priority)]


def _main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog='camera_stream')
    sub = parser.add_subparsers(dest='role', required=True)
    pub = sub.add_parser('publish')
    pub.add_argument('frames', help='.npy file of mono8 frames')
    pub.add_argument('rate', type=float)
    pub.add_argument('--realtime-priority', type=int, default=0)
    echo_args = sub.add_parser('echo')
    echo_args.add_argument('--realtime-priority', type=int, default=0)
    args = parser.parse_args(argv)
    if args.role == 'echo':
        return echo(args.realtime_priority)
    return publish(args.frames, args.rate, args.realtime_priority)


if __name__ == '__main__':
    sys.exit(_main())
