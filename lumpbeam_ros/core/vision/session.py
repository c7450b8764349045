"""A camera stream through the tracker: camera info, frames in, poses out, and the tally.

The camera node and ``lumpbeam track`` both drive a :class:`TrackingSession`; it owns the
tracker (rebuilt when the camera info changes), turns undecodable messages into a failed
:class:`~lumpbeam_ros.core.vision.tracker.TrackResult` like any other bad frame, and counts what
happened for the node's diagnostics and the command's summary.
"""

from __future__ import annotations

import math
from collections import Counter
from dataclasses import dataclass, field

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import IMAGE_TYPE
from lumpbeam_ros.core.vision.camera_model import CameraInfo
from lumpbeam_ros.core.vision.config import CameraConfig
from lumpbeam_ros.core.vision.free_pose import POSE_MODELS
from lumpbeam_ros.core.vision.messages import (
    HEADER_STAMP_END,
    CameraFrame,
    decode_camera_info,
    decode_frame,
)
from lumpbeam_ros.core.vision.tracker import TipTracker, TrackResult, TrackStatus


@dataclass
class SessionStats:
    """What a session has seen.

    Attributes:
        frames_in: Frames offered (decodable or not).
        poses_out: Frames that gave a pose.
        lost: Frames without a pose, by :class:`TrackStatus` value.
        last_reason: Why the latest frame without a pose had none.
        last_stamp: Stamp of the latest frame, s (NaN before the first).
    """

    frames_in: int = 0
    poses_out: int = 0
    lost: Counter[str] = field(default_factory=Counter)
    last_reason: str = ''
    last_stamp: float = math.nan

    @property
    def frames_lost(self) -> int:
        """Frames without a pose."""
        return self.frames_in - self.poses_out


def _same_camera(a: CameraInfo, b: CameraInfo) -> bool:
    return (
        a.width == b.width
        and a.height == b.height
        and np.array_equal(a.k, b.k)
        and np.array_equal(a.d, b.d)
    )


class TrackingSession:
    """Tracks one camera's frames.

    Args:
        config: Rig geometry and tracker settings.
        camera_info: The intrinsics if known now; otherwise frames are refused (status
            ``NO_CAMERA_INFO``) until :meth:`set_camera_info` is called.
        pose_model: ``'plane'`` or ``'free'`` (see :class:`TipTracker`).

    Raises:
        LumpbeamError: ``camera_info`` and ``config`` cannot work together (see
            :class:`~lumpbeam_ros.core.vision.tracker.TipTracker`), or an unknown pose model.
    """

    def __init__(
        self,
        config: CameraConfig,
        camera_info: CameraInfo | None = None,
        pose_model: str = 'plane',
    ):
        if pose_model not in POSE_MODELS:
            raise LumpbeamError(
                f'pose model {pose_model!r} is not one of {", ".join(POSE_MODELS)}'
            )
        self.config = config
        self.pose_model = pose_model
        self.stats = SessionStats()
        self._tracker: TipTracker | None = None
        # What follows the stamp in the last camera info message taken (None: none taken).
        self._camera_info_body: bytes | None = None
        if camera_info is not None:
            self.set_camera_info(camera_info)

    @property
    def camera_info(self) -> CameraInfo | None:
        """The intrinsics in use, or ``None`` while waiting for them."""
        return None if self._tracker is None else self._tracker.camera_info

    @property
    def tracker(self) -> TipTracker | None:
        """The tracker, once the intrinsics are known."""
        return self._tracker

    def set_camera_info(self, info: CameraInfo) -> bool:
        """Takes the camera's intrinsics; a change starts a fresh tracker.

        A camera publishes its info with every frame, so an unchanged one is a no-op and the
        tracking (and its rig calibration) carries on.

        Args:
            info: The intrinsics.

        Returns:
            Whether the tracker was (re)built.

        Raises:
            LumpbeamError: The board is not in view with these intrinsics; the previous
                tracker, if any, is kept.
        """
        if self._tracker is not None and _same_camera(self._tracker.camera_info, info):
            return False
        self._tracker = TipTracker(info, self.config, self.pose_model)
        return True

    def set_camera_info_message(self, data: bytes | memoryview) -> bool:
        """Takes a serialized ``sensor_msgs/msg/CameraInfo`` (:meth:`set_camera_info`).

        A camera sends the same intrinsics beside every frame under a new stamp: a message
        equal to the last one taken but for its stamp is not decoded again (at 180 frames a
        second the decoding was a tenth of the camera node's CPU).

        Args:
            data: The CDR bytes.

        Returns:
            Whether the tracker was (re)built.

        Raises:
            BagError: Corrupt bytes.
            LumpbeamError: An unusable calibration, or the board is not in view with it; the
                previous tracker, if any, is kept.
        """
        body = bytes(data[HEADER_STAMP_END:])
        if body == self._camera_info_body and self._tracker is not None:
            return False
        self._camera_info_body = None  # until this one is taken
        changed = self.set_camera_info(decode_camera_info(data))
        self._camera_info_body = body
        return changed

    def process(self, pixels: np.ndarray, stamp: float, encoding: str = 'mono8') -> TrackResult:
        """Tracks one frame and counts it.

        Args:
            pixels: H x W or H x W x 3 uint8 array.
            stamp: Exposure time, s.
            encoding: ``'mono8'``, ``'bgr8'`` or ``'rgb8'``.

        Returns:
            The result; never raises for bad pixels.
        """
        if self._tracker is None:
            result = TrackResult(
                float(stamp), TrackStatus.NO_CAMERA_INFO, 'no camera_info received yet'
            )
        else:
            result = self._tracker.process(pixels, stamp, encoding)
        return self._count(result)

    def process_message(
        self, data: bytes | memoryview, msgtype: str = IMAGE_TYPE
    ) -> tuple[CameraFrame | None, TrackResult]:
        """Decodes a serialized image message and tracks it.

        Args:
            data: CDR bytes.
            msgtype: ``sensor_msgs/msg/Image`` or ``sensor_msgs/msg/CompressedImage``.

        Returns:
            The decoded frame (``None`` when undecodable; its ``stamp_ns`` is what a pose
            message carries) and the result; a corrupt or unsupported message is a
            ``BAD_IMAGE`` result.
        """
        try:
            frame = decode_frame(data, msgtype)
        except LumpbeamError as exc:
            return None, self.reject(str(exc))
        return frame, self.process(frame.pixels, frame.stamp, frame.encoding)

    def reject(self, reason: str, stamp: float = math.nan) -> TrackResult:
        """Counts a frame that could not be decoded (a ``BAD_IMAGE`` result).

        Args:
            reason: One line: what was wrong with it.
            stamp: Its stamp when known, s.

        Returns:
            The result.
        """
        return self._count(TrackResult(stamp, TrackStatus.BAD_IMAGE, reason))

    def _count(self, result: TrackResult) -> TrackResult:
        stats = self.stats
        stats.frames_in += 1
        stats.last_stamp = result.stamp
        if result.ok:
            stats.poses_out += 1
        else:
            stats.lost[result.status.value] += 1
            stats.last_reason = result.reason or result.status.value
        return result
