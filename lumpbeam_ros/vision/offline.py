"""The camera pipeline over a bag, offline: ``lumpbeam track BAG OUT`` (SPEC section 5).

OUT is a copy of BAG plus ``/tip_pose``: every other topic is copied as its stored CDR bytes
(never decoded), with its type, definition and offered QoS; the images are tracked on the
way and each pose is written right after its image, stamped with the image's stamp and
logged at the image's log time. A ``/tip_pose`` already in BAG is replaced by the tracked
one (the summary says so). The frames go through the same
:class:`~lumpbeam_ros.vision.session.TrackingSession` as the camera node's.
"""

from __future__ import annotations

import time
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from mcap.reader import SeekingReader

from lumpbeam_ros.bagio import BagReader, BagWriter, convert, read_camera_info, read_tip_poses
from lumpbeam_ros.bagio.qos import from_dict
from lumpbeam_ros.bagio.typestore import is_known
from lumpbeam_ros.errors import BagError, LumpbeamError
from lumpbeam_ros.vision.config import CameraConfig
from lumpbeam_ros.vision.free_pose import rpy_quaternion
from lumpbeam_ros.vision.messages import camera_info_from_data, decode_camera_info
from lumpbeam_ros.vision.session import TrackingSession
from lumpbeam_ros.vision.tracker import TrackResult

POSE_TOPIC = '/tip_pose'
TRUTH_TOPIC = '/tip_pose_truth'
IMAGE_TOPIC = '/camera/image_raw'
CAMERA_INFO_TOPIC = '/camera/camera_info'


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
        z_rms_um: RMS error of z against ``/tip_pose_truth``, um (NaN without truth).
        pitch_rms_mrad: RMS error of the pitch against the truth, mrad (NaN without).
        z_bias_um: Mean z error against the truth, um (NaN without).
        compared: Poses matched to a truth sample by stamp.
    """

    frames: int = 0
    poses: int = 0
    lost_by_reason: dict[str, int] = field(default_factory=dict)
    fps: float = float('nan')
    replaced_poses: int = 0
    skipped_topics: list[str] = field(default_factory=list)
    z_rms_um: float = float('nan')
    pitch_rms_mrad: float = float('nan')
    z_bias_um: float = float('nan')
    compared: int = 0

    @property
    def lost(self) -> int:
        """Frames without a pose."""
        return self.frames - self.poses


def _definitions(reader: BagReader) -> dict[str, tuple[str, str]]:
    """The ``(encoding, text)`` message definitions the MCAP files store, by topic."""
    found: dict[str, tuple[str, str]] = {}
    for file in reader.info.files:
        if file in reader.truncated:
            continue  # no summary to read them from; known types need none
        with file.open('rb') as stream:
            summary = SeekingReader(stream).get_summary()
        if summary is None:
            continue
        for channel in summary.channels.values():
            schema = summary.schemas.get(channel.schema_id)
            if schema is not None:
                found[channel.topic] = (schema.encoding, schema.data.decode(errors='replace'))
    return found


def _declare_copies(reader: BagReader, out: BagWriter, summary: TrackSummary) -> set[str]:
    """Declares BAG's topics (but ``/tip_pose``) in OUT; returns those to copy."""
    definitions: dict[str, tuple[str, str]] | None = None
    copied = set()
    for name, entry in reader.topics.items():
        if name == POSE_TOPIC:
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


def pose_message(stamp_ns: int, result: TrackResult) -> object:
    """The ``/tip_pose`` message of a tracked frame (6-DoF with the free model)."""
    if result.pose6 is not None:
        p = result.pose6
        return convert.pose_stamped_6dof(
            stamp_ns, tuple(p[:3]), rpy_quaternion(*p[3:]), 'beam_base'
        )
    x, z, pitch = (float(v) for v in result.pose)
    return convert.pose_stamped(stamp_ns, x, z, pitch, 'beam_base')


def track_bag(
    bag: str | Path,
    out: str | Path,
    config: CameraConfig,
    image_topic: str = IMAGE_TOPIC,
    camera_info_topic: str = CAMERA_INFO_TOPIC,
    pose_model: str = 'plane',
) -> TrackSummary:
    """Tracks a bag's images and writes OUT = BAG + ``/tip_pose``.

    Args:
        bag: The input bag folder.
        out: The bag folder to create (must not exist).
        config: Rig geometry and tracker settings; the intrinsics come from the bag.
        image_topic: The images to track.
        camera_info_topic: The camera's calibration (the first message is used, and any
            later change is followed).
        pose_model: ``'plane'`` or ``'free'`` (the full 6-DoF pose is written).

    Returns:
        The summary.

    Raises:
        BagError: OUT exists; BAG is not a bag, has no images or no camera info.
        LumpbeamError: The camera info is unusable (e.g. K = 0).
    """
    out = Path(out)
    if out.exists():
        raise BagError(f'{out} exists already; a bag is never overwritten')
    reader = BagReader(bag)
    images = reader.require(image_topic, 'sensor_msgs/msg/Image')
    if images.count == 0:
        raise BagError(f'{reader.path}: topic {image_topic} has no images')
    reader.require(camera_info_topic, 'sensor_msgs/msg/CameraInfo')
    info = camera_info_from_data(read_camera_info(reader, camera_info_topic))
    session = TrackingSession(config, info, pose_model)
    summary = TrackSummary()
    tracking_s = 0.0
    with BagWriter(out) as writer:
        copied = _declare_copies(reader, writer, summary)
        writer.add_topic(POSE_TOPIC, 'geometry_msgs/msg/PoseStamped')
        for raw in reader.iter_raw():
            if raw.topic == POSE_TOPIC:
                summary.replaced_poses += 1
                continue
            if raw.topic in copied:
                writer.write_raw(raw.topic, raw.log_time_ns, raw.data)
            if raw.topic == camera_info_topic:
                try:
                    session.set_camera_info(decode_camera_info(raw.data))
                except LumpbeamError:
                    pass  # a bad calibration message: keep the one in use
            elif raw.topic == image_topic:
                start = time.perf_counter()
                frame, result = session.process_message(raw.data)
                tracking_s += time.perf_counter() - start
                if frame is not None and result.ok:
                    msg = pose_message(frame.stamp_ns, result)
                    writer.write_message(POSE_TOPIC, msg, raw.log_time_ns)
    stats = session.stats
    summary.frames, summary.poses = stats.frames_in, stats.poses_out
    summary.lost_by_reason = dict(Counter(stats.lost))
    summary.fps = stats.frames_in / tracking_s if tracking_s > 0 else float('nan')
    if TRUTH_TOPIC in reader.topics and summary.poses:
        _compare_with_truth(out, summary)
    return summary
