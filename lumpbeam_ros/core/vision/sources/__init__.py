"""Camera footage from anywhere a lab keeps it, for ``lumpbeam track`` and the camera node.

ROS-free readers, each yielding :class:`~lumpbeam_ros.core.vision.sources.frame.FootageFrame`
with tracker-ready pixels and a stamp:

- :class:`~lumpbeam_ros.core.vision.sources.video.VideoSource`: a video file;
- :class:`~lumpbeam_ros.core.vision.sources.folder.FolderSource`: a folder of images;
- :class:`~lumpbeam_ros.core.vision.sources.video.DeviceSource`: a live capture device.

Bags are read by :mod:`lumpbeam_ros.core.bagio` and decoded by
:mod:`lumpbeam_ros.core.vision.messages` (raw ``sensor_msgs/Image`` in every encoding of
:mod:`.pixels`, and ``sensor_msgs/CompressedImage``). The intrinsics of footage come from a ROS
camera calibration file (:mod:`lumpbeam_ros.core.vision.camera_info_file`).
"""

from __future__ import annotations

from pathlib import Path

from lumpbeam_ros.core.bagio.metadata import is_bag
from lumpbeam_ros.core.vision.sources.folder import FolderSource
from lumpbeam_ros.core.vision.sources.frame import FootageFrame
from lumpbeam_ros.core.vision.sources.stamps import FootageError, FrameStamps
from lumpbeam_ros.core.vision.sources.video import DeviceSource, VideoSource

__all__ = [
    'DeviceSource',
    'FolderSource',
    'FootageError',
    'FootageFrame',
    'FrameStamps',
    'VideoSource',
    'is_bag',
    'open_footage',
]


def open_footage(
    path: str | Path, stamps: FrameStamps | None, how_to_stamp: str = 'a frame rate'
) -> VideoSource | FolderSource:
    """Opens a video file or an image folder.

    Args:
        path: The file or folder (a bag is not footage: see :func:`is_bag`).
        stamps: The stamps; ``None`` is an error (footage has no clock of its own).
        how_to_stamp: How the caller's user gives stamps, for that error
            (``'--fps HZ or --timestamps FILE'``).

    Returns:
        The source.

    Raises:
        FootageError: No stamps, a missing path, or what the sources raise.
    """
    path = Path(path)
    if not path.exists():
        raise FootageError(f'{path}: no such file or folder')
    if stamps is None:
        kind = 'an image folder' if path.is_dir() else 'a video'
        raise FootageError(f'{path} is {kind} without stamps: give {how_to_stamp}')
    return FolderSource(path, stamps) if path.is_dir() else VideoSource(path, stamps)
