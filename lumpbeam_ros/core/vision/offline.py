"""The camera pipeline over recorded footage, offline: ``lumpbeam track SRC OUT``.

From a bag (:func:`track_bag`), OUT is a copy of it plus ``/tip_pose``: every other topic is
copied as its stored CDR bytes (never decoded), with its type, definition and offered QoS,
but the images (``sensor_msgs/Image`` or ``sensor_msgs/CompressedImage``, nearly all of a
camera bag's bytes) only when asked. The images are tracked on the way and each pose is
written at its image's log time (right after it, when kept), stamped with the image's stamp.
A ``/tip_pose`` already in the bag is replaced by the tracked one (the summary says so).
``/beam_markers`` (at most 30 Hz: the tracked tip and the checkerboard, for a viewer;
:mod:`lumpbeam_ros.core.viz.markers`) is written beside the poses, replacing any the bag had.
From a video or an image folder (:func:`track_footage`), OUT holds ``/tip_pose`` and the
``/camera/camera_info`` used, stamped as the footage's stamps say. The frames go through the
same :class:`~lumpbeam_ros.core.vision.session.TrackingSession` as the camera node's.

A frame that does not decode is a lost frame (counted, and the first of each kind named in
the summary); an image whose size is not the camera's stops the run with an error, and OUT,
incomplete, is removed; so is OUT when no frame gave a pose, when the run is interrupted, or
when the poses are more than :data:`MAX_TRUTH_GAP_M` from the bag's ``/tip_pose_truth``.
"""

from __future__ import annotations

import shutil
import time
from collections import Counter
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from lumpbeam_ros.base.errors import BagError, LumpbeamError
from lumpbeam_ros.base.interface import (
    BASE_FRAME,
    CAMERA_INFO,
    CAMERA_INFO_TYPE,
    COMPRESSED_IMAGE,
    IMAGE,
    POSE_STAMPED,
    TIP_POSE,
    TIP_POSE_TRUTH,
)
from lumpbeam_ros.core.bagio import BagReader, BagWriter, convert, read_camera_info, read_tip_poses
from lumpbeam_ros.core.bagio.qos import from_dict
from lumpbeam_ros.core.bagio.typestore import is_known
from lumpbeam_ros.core.vision.bag_frames import bag_frames
from lumpbeam_ros.core.vision.camera_model import CameraInfo
from lumpbeam_ros.core.vision.config import CameraConfig
from lumpbeam_ros.core.vision.free_pose import rpy_quaternion
from lumpbeam_ros.core.vision.messages import (
    IMAGE_TYPES,
    camera_info_from_data,
    camera_info_to_data,
)
from lumpbeam_ros.core.vision.placement import board_placement
from lumpbeam_ros.core.vision.session import TrackingSession
from lumpbeam_ros.core.vision.sources import FootageError, FootageFrame
from lumpbeam_ros.core.vision.tracker import TrackResult
from lumpbeam_ros.core.viz.marker_messages import write_scene_ns
from lumpbeam_ros.core.viz.markers import (
    MARKERS_TOPIC,
    BeamScene,
    TipPoint,
    lifetime_for_rate,
)

POSE_TOPIC = TIP_POSE
TRUTH_TOPIC = TIP_POSE_TRUTH
IMAGE_TOPIC = IMAGE
COMPRESSED_IMAGE_TOPIC = COMPRESSED_IMAGE
CAMERA_INFO_TOPIC = CAMERA_INFO

#: Rate of ``/beam_markers`` in OUT, Hz: at most one array per period of it.
MARKERS_RATE_HZ = 30.0

#: The largest z RMS against ``/tip_pose_truth`` a run may end with, m. The tracker is good
#: to microns; a centimetre means a rig other than the one filmed (an arm's board, placed
#: where that arm rests, tracked with the beam's camera file was 641 mm off).
MAX_TRUTH_GAP_M = 0.01

#: Called after each frame with the frames done and the frames expected (``None``: unknown).
ProgressCallback = Callable[[int, 'int | None'], None]


@dataclass
class TrackSummary:
    """What ``lumpbeam track`` did.

    Attributes:
        frames: Images read.
        poses: Poses written.
        lost_by_reason: Frames without a pose, by status.
        fps: Frames tracked per second of tracking (decoding included, copying not).
        replaced_poses: Messages of BAG's own ``/tip_pose`` that were dropped (0: none).
        skipped_topics: Topics not copied (a type without a definition in BAG).
        images_left_out: Image topics not copied (``keep_images`` not set).
        z_rms_um: RMS error of z against ``/tip_pose_truth``, um (NaN without truth).
        pitch_rms_mrad: RMS error of the pitch against the truth, mrad (NaN without).
        z_bias_um: Mean z error against the truth, um (NaN without).
        compared: Poses matched to a truth sample by stamp.
        first_problems: For each kind of lost frame, the first one: which frame and why.
        image_topic: The bag topic tracked (empty for footage).
    """

    frames: int = 0
    poses: int = 0
    lost_by_reason: dict[str, int] = field(default_factory=dict)
    fps: float = float('nan')
    replaced_poses: int = 0
    skipped_topics: list[str] = field(default_factory=list)
    images_left_out: list[str] = field(default_factory=list)
    z_rms_um: float = float('nan')
    pitch_rms_mrad: float = float('nan')
    z_bias_um: float = float('nan')
    compared: int = 0
    first_problems: dict[str, str] = field(default_factory=dict)
    image_topic: str = ''

    @property
    def lost(self) -> int:
        """Frames without a pose."""
        return self.frames - self.poses


def _definitions(reader: BagReader) -> dict[str, tuple[str, str]]:
    """The ``(encoding, text)`` message definitions the MCAP files store, by topic."""
    return {
        topic: (schema.encoding, schema.data.decode(errors='replace'))
        for topic, schema in reader.schemas().items()
    }


def _declare_copies(
    reader: BagReader, out: BagWriter, summary: TrackSummary, keep_images: bool
) -> set[str]:
    """Declares BAG's topics (but ``/tip_pose``, ``/beam_markers``) in OUT; returns the copied."""
    definitions: dict[str, tuple[str, str]] | None = None
    copied = set()
    for name, entry in reader.topics.items():
        if name in (POSE_TOPIC, MARKERS_TOPIC):
            continue  # written anew from the tracked poses
        if entry.msgtype in IMAGE_TYPES and not keep_images:
            summary.images_left_out.append(name)
            continue
        msgdef = None
        if not is_known(entry.msgtype):
            definitions = _definitions(reader) if definitions is None else definitions
            encoding, text = definitions.get(name, ('', ''))
            if encoding != 'ros2msg' or not text:
                summary.skipped_topics.append(name)
                continue
            msgdef = text
        qos = [from_dict(q) for q in entry.qos if isinstance(q, dict)] or None
        out.add_topic(name, entry.msgtype, qos, msgdef, entry.type_hash or None)
        copied.add(name)
    return copied


def _compare_with_truth(out: Path, summary: TrackSummary) -> None:
    truth = read_tip_poses(out, TRUTH_TOPIC)
    poses = read_tip_poses(out, POSE_TOPIC)
    if truth.t.size == 0 or poses.t.size == 0:
        return
    index = np.clip(np.searchsorted(truth.t, poses.t), 0, truth.t.size - 1)
    # Same stamps to the nanosecond in a synthetic bag; allow for float seconds.
    match = np.abs(truth.t[index] - poses.t) < 1e-6
    if not np.any(match):
        return
    dz = poses.z[match] - truth.z[index[match]]
    dpitch = poses.pitch[match] - truth.pitch[index[match]]
    summary.compared = int(np.sum(match))
    summary.z_rms_um = float(np.sqrt(np.mean(dz**2)) * 1e6)
    summary.z_bias_um = float(np.mean(dz) * 1e6)
    summary.pitch_rms_mrad = float(np.sqrt(np.mean(dpitch**2)) * 1e3)


def _choose_image_topic(reader: BagReader, image_topic: str | None) -> str:
    """The topic to track: the one asked for, else the camera's raw or compressed images."""
    images = {n: e for n, e in reader.topics.items() if e.msgtype in IMAGE_TYPES}
    if image_topic is not None:
        entry = reader.require(image_topic)
        if entry.msgtype not in IMAGE_TYPES:
            raise BagError(
                f'{reader.path}: topic {image_topic} has type {entry.msgtype}, not an image '
                f'({", ".join(IMAGE_TYPES)})'
            )
        return image_topic
    for preferred in (IMAGE_TOPIC, COMPRESSED_IMAGE_TOPIC):
        if preferred in images:
            return preferred
    if len(images) == 1:
        return next(iter(images))
    listed = ', '.join(sorted(images)) if images else 'none'
    raise BagError(
        f'{reader.path}: no topic {IMAGE_TOPIC} (image topics: {listed}; choose one with '
        f'--image-topic)'
    )


def _check_size(pixels: object, info: CameraInfo, label: str, info_source: str) -> None:
    """Stops the run on an image whose size is not the camera's.

    Raises:
        FootageError: The size differs (mixed sizes, or a calibration of another camera).
    """
    height, width = getattr(pixels, 'shape', (0, 0))[:2]
    if (width, height) != (info.width, info.height):
        raise FootageError(
            f'{label}: image is {width} x {height} px but the camera info ({info_source}) '
            f'is {info.width} x {info.height} px'
        )


class _Run:
    """One tracking run: the session, the pose output, the tally and the progress.

    Args:
        session: The tracking session (with its intrinsics).
        writer: OUT; ``/tip_pose`` is declared on it.
        source: The input, for messages.
        info_source: Where the intrinsics came from, for messages.
        total: Frames expected (``None``: unknown).
        progress: Called after each frame.
    """

    def __init__(
        self,
        session: TrackingSession,
        writer: BagWriter,
        source: str,
        info_source: str,
        total: int | None,
        progress: ProgressCallback | None,
    ):
        self.session = session
        self.writer = writer
        self.source = source
        self.info_source = info_source
        self.total = total
        self.progress = progress
        self.summary = TrackSummary()
        self.tracking_s = 0.0
        self.done = 0
        writer.add_topic(POSE_TOPIC, POSE_STAMPED)
        self._board = board_placement(session.config)
        self._next_markers_ns = -1

    def track(
        self, label: str, stamp_ns: int, pixels: np.ndarray, encoding: str, log_time_ns: int
    ) -> None:
        """Tracks one decoded frame and writes its pose.

        Raises:
            FootageError: The image's size is not the camera's.
        """
        info = self.session.camera_info
        if info is not None:
            _check_size(pixels, info, label, self.info_source)
        start = time.perf_counter()
        result = self.session.process(pixels, convert.ns_to_seconds(stamp_ns), encoding)
        self.tracking_s += time.perf_counter() - start
        if result.ok:
            self.writer.write_message(POSE_TOPIC, pose_message(stamp_ns, result), log_time_ns)
            if stamp_ns >= self._next_markers_ns:
                self._write_markers(stamp_ns, log_time_ns, result)
        else:
            self._note(label, result.status.value, result.reason)
        self._tick()

    def _write_markers(self, stamp_ns: int, log_time_ns: int, result: TrackResult) -> None:
        assert result.pose is not None  # markers are drawn for tracked frames only
        x, z, _ = (float(v) for v in result.pose)  # the planar part, also of a 6-DoF fit
        scene = BeamScene(0.0, measured=TipPoint(x, z), board=self._board)
        # The frame's own integer stamp and log time: the markers sort with its pose.
        lifetime = lifetime_for_rate(MARKERS_RATE_HZ)
        write_scene_ns(self.writer, stamp_ns, scene, lifetime, log_time_ns=log_time_ns)
        self._next_markers_ns = stamp_ns + convert.seconds_to_ns(1.0 / MARKERS_RATE_HZ)

    def reject(self, label: str, reason: str) -> None:
        """Counts a frame that did not decode."""
        self.session.reject(reason)
        self._note(label, 'bad_image', reason)
        self._tick()

    def finish(self) -> TrackSummary:
        """Fills in the summary.

        Raises:
            FootageError: Not one frame was read, or not one gave a pose (OUT would hold
                no ``/tip_pose``).
        """
        stats, summary = self.session.stats, self.summary
        if stats.frames_in == 0:
            raise FootageError(f'{self.source}: no frames at all')
        if stats.poses_out == 0:
            lost = ', '.join(f'{k} {v}' for k, v in sorted(Counter(stats.lost).items()))
            first = '; '.join(w for _, w in sorted(summary.first_problems.items()))
            raise FootageError(
                f'{self.source}: no pose in any of its {stats.frames_in} frames ({lost}); '
                f'first: {first}'
            )
        summary.frames, summary.poses = stats.frames_in, stats.poses_out
        summary.lost_by_reason = dict(Counter(stats.lost))
        summary.fps = stats.frames_in / self.tracking_s if self.tracking_s > 0 else float('nan')
        return summary

    def _note(self, label: str, status: str, reason: str) -> None:
        self.summary.first_problems.setdefault(status, f'{label}: {reason or status}')

    def _tick(self) -> None:
        self.done += 1
        if self.progress is not None:
            self.progress(self.done, self.total)


def _removing_on_error(out: Path, write: Callable[[], TrackSummary]) -> TrackSummary:
    """Runs ``write``; removes the incomplete OUT when the input is unusable or on Ctrl-C."""
    try:
        return write()
    except (LumpbeamError, KeyboardInterrupt):
        shutil.rmtree(out, ignore_errors=True)
        raise


def pose_message(stamp_ns: int, result: TrackResult) -> object:
    """The ``/tip_pose`` message of a tracked frame (6-DoF with the free model)."""
    if result.pose6 is not None:
        p = result.pose6
        return convert.pose_stamped_6dof(
            stamp_ns, tuple(p[:3]), rpy_quaternion(*p[3:]), BASE_FRAME
        )
    assert result.pose is not None  # called for tracked frames only
    x, z, pitch = (float(v) for v in result.pose)
    return convert.pose_stamped(stamp_ns, x, z, pitch, BASE_FRAME)


def track_bag(
    bag: str | Path,
    out: str | Path,
    config: CameraConfig,
    image_topic: str | None = None,
    camera_info_topic: str = CAMERA_INFO_TOPIC,
    camera_info: CameraInfo | None = None,
    camera_info_source: str = '',
    progress: ProgressCallback | None = None,
    pose_model: str = 'plane',
    keep_images: bool = False,
) -> TrackSummary:
    """Tracks a bag's images and writes OUT = BAG + ``/tip_pose`` (the images only if asked).

    Args:
        bag: The input bag folder.
        out: The bag folder to create (must not exist).
        config: Rig geometry and tracker settings.
        image_topic: The images to track (``Image`` or ``CompressedImage``); ``None``
            takes ``/camera/image_raw``, else ``/camera/image_raw/compressed``, else the
            bag's only image topic.
        camera_info_topic: The camera's calibration in the bag (the first message is used,
            and any later change is followed); not needed with ``camera_info``.
        camera_info: Intrinsics to use instead of the bag's (e.g. from a calibration file).
        camera_info_source: Where ``camera_info`` came from, for messages.
        progress: Called after each image.
        pose_model: ``'plane'`` or ``'free'`` (the full 6-DoF pose is written).
        keep_images: Also copy BAG's image topics.

    Returns:
        The summary.

    Raises:
        BagError: OUT exists; BAG is not a bag, has no images or no camera info.
        FootageError: An image of another size than the camera info says, or poses more
            than :data:`MAX_TRUTH_GAP_M` from the bag's ``/tip_pose_truth``.
        LumpbeamError: The camera info is unusable (e.g. K = 0).
    """
    out = Path(out)
    if out.exists():
        raise BagError(f'{out} exists already; a bag is never overwritten')
    reader = BagReader(bag)
    image_topic = _choose_image_topic(reader, image_topic)
    entry = reader.topics[image_topic]
    if entry.count == 0:
        raise BagError(f'{reader.path}: topic {image_topic} has no images')
    follow_info = camera_info is None
    if camera_info is None:
        reader.require(camera_info_topic, CAMERA_INFO_TYPE)
        data = read_camera_info(reader, camera_info_topic)
        try:
            camera_info = camera_info_from_data(data)
        except LumpbeamError as exc:
            raise BagError(f'{reader.path}: {camera_info_topic}: {exc}') from None
        camera_info_source = f'{camera_info_topic} of {reader.path}'
    session = TrackingSession(config, camera_info, pose_model)

    def write() -> TrackSummary:
        with BagWriter(out) as writer:
            name = str(reader.path)
            run = _Run(session, writer, name, camera_info_source, entry.count, progress)
            copied = _declare_copies(reader, writer, run.summary, keep_images)
            items = bag_frames(
                reader, session, image_topic, entry.msgtype, camera_info_topic,
                follow_info=follow_info,
            )  # fmt: skip
            for item in items:
                raw = item.raw
                if raw.topic == POSE_TOPIC:
                    run.summary.replaced_poses += 1
                    continue
                if raw.topic in copied:
                    writer.write_raw(raw.topic, raw.log_time_ns, raw.data)
                # A bad calibration message (item.problem) leaves the one in use.
                if item.kind != 'image':
                    continue
                label = f'{reader.path} {image_topic} message {item.index}'
                if item.frame is None:
                    run.reject(label, item.problem)
                    continue
                frame = item.frame
                run.track(label, frame.stamp_ns, frame.pixels, frame.encoding, raw.log_time_ns)
        return run.finish()

    summary = _removing_on_error(out, write)
    summary.image_topic = image_topic
    if TRUTH_TOPIC in reader.topics and summary.poses:
        _compare_with_truth(out, summary)
        if summary.z_rms_um > MAX_TRUTH_GAP_M * 1e6:
            shutil.rmtree(out, ignore_errors=True)
            raise FootageError(
                f'{reader.path}: the tracked tip is {summary.z_rms_um * 1e-3:.1f} mm (z RMS) '
                f'from {TRUTH_TOPIC}: the board or the rig of the camera file is not the one '
                f'filmed; {out} removed'
            )
    return summary


def track_footage(
    frames: Iterable[FootageFrame],
    out: str | Path,
    config: CameraConfig,
    camera_info: CameraInfo,
    source: str,
    camera_info_source: str,
    total: int | None = None,
    progress: ProgressCallback | None = None,
    pose_model: str = 'plane',
) -> TrackSummary:
    """Tracks a video's or an image folder's frames into OUT: ``/tip_pose`` and the intrinsics.

    Args:
        frames: The footage (a :mod:`~lumpbeam_ros.core.vision.sources` reader).
        out: The bag folder to create (must not exist).
        config: Rig geometry and tracker settings.
        camera_info: The intrinsics (written once to ``/camera/camera_info``, at the first
            frame's stamp).
        source: The footage, for messages.
        camera_info_source: Where the intrinsics came from, for messages.
        total: Frames expected, for the progress (``None``: unknown).
        progress: Called after each frame.
        pose_model: ``'plane'`` or ``'free'`` (the full 6-DoF pose is written).

    Returns:
        The summary.

    Raises:
        BagError: OUT exists.
        FootageError: An image of another size than the camera's, stamps that run out
            before the footage, no frame at all.
        LumpbeamError: The intrinsics do not fit the configuration.
    """
    out = Path(out)
    if out.exists():
        raise BagError(f'{out} exists already; a bag is never overwritten')
    session = TrackingSession(config, camera_info, pose_model)

    def write() -> TrackSummary:
        with BagWriter(out) as writer:
            run = _Run(session, writer, source, camera_info_source, total, progress)
            for frame in frames:
                if frame.index == 0:
                    info = convert.camera_info(frame.stamp_ns, camera_info_to_data(camera_info))
                    writer.write_message(CAMERA_INFO_TOPIC, info, frame.stamp_ns)
                if frame.pixels is None:
                    run.reject(frame.label, frame.problem)
                else:
                    run.track(frame.label, frame.stamp_ns, frame.pixels, frame.encoding,
                              frame.stamp_ns)  # fmt: skip
        return run.finish()

    return _removing_on_error(out, write)
