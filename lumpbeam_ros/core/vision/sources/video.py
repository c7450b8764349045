"""Frames through OpenCV's capture API: a video file, or a live camera device.

:class:`VideoSource` reads a recorded video (any container and codec the installed OpenCV
reads; ``opencv-python-headless`` reads through its bundled FFmpeg) with stamps from a frame
rate or a timestamps file. :class:`DeviceSource` reads a live device (``0`` for
``/dev/video0``, a device path, or any URL or file OpenCV opens) and stamps each frame with a
clock read right after the frame was grabbed, so the stamp includes the driver's latency.
Both read through :class:`CaptureReader`, so a video file given as a device exercises the live
path.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from pathlib import Path

import cv2
import numpy as np

from lumpbeam_ros.core.vision.sources.frame import FootageFrame
from lumpbeam_ros.core.vision.sources.pixels import decoded_file_pixels
from lumpbeam_ros.core.vision.sources.stamps import FootageError, FrameStamps


class CaptureReader:
    """An opened ``cv2.VideoCapture`` whose first frame has been read.

    Args:
        target: A file path, a device path or URL, or a device index.
        name: How to call it in messages.

    Raises:
        FootageError: OpenCV cannot open it or cannot read a first frame from it.
    """

    def __init__(self, target: str | int, name: str):
        self.name = name
        self._capture = cv2.VideoCapture(target)
        if not self._capture.isOpened():
            raise FootageError(f'{name}: OpenCV cannot open it as a video')
        if not self._capture.grab():
            self._capture.release()
            raise FootageError(f'{name}: no frame could be read (an empty or corrupt video)')
        self._grabbed = True

    @property
    def frame_count(self) -> int | None:
        """Frames the container declares (``None`` when it does not say, e.g. a device)."""
        count = self._capture.get(cv2.CAP_PROP_FRAME_COUNT)
        return int(count) if count and count > 0 else None

    def frames(self, on_grab: Callable[[int], None] | None = None) -> Iterator[np.ndarray]:
        """Yields the decoded frames (BGR or grey, as the capture gives them) until the end.

        Args:
            on_grab: Called with the frame number right after each grab (to read a clock).
        """
        index = 0
        try:
            while self._grabbed:
                if on_grab is not None:
                    on_grab(index)
                ok, pixels = self._capture.retrieve()
                if not ok or pixels is None:
                    return
                yield pixels
                index += 1
                self._grabbed = self._capture.grab()
        finally:
            self._capture.release()

    def close(self) -> None:
        """Releases the capture."""
        self._grabbed = False
        self._capture.release()


class VideoSource:
    """A recorded video.

    Args:
        path: The video file.
        stamps: Stamp of each frame.

    Raises:
        FootageError: Not a file OpenCV reads, no frame in it, or fewer stamps than the
            frames its container declares.
    """

    kind = 'video'

    def __init__(self, path: str | Path, stamps: FrameStamps):
        self.path = Path(path)
        if not self.path.is_file():
            raise FootageError(f'{self.path}: no such video file')
        self.stamps = stamps
        self._reader = CaptureReader(str(self.path), str(self.path))
        self.total = self._reader.frame_count
        if self.total is not None:
            try:
                stamps.check_covers(self.total, str(self.path))
            except FootageError:
                self._reader.close()
                raise

    def __iter__(self) -> Iterator[FootageFrame]:
        """Yields every frame with its stamp.

        Raises:
            FootageError: The timestamps file ends before the video.
        """
        name = self.path.name
        for index, pixels in enumerate(self._reader.frames()):
            stamp_ns = self.stamps.ns(index, str(self.path))
            image, encoding = decoded_file_pixels(pixels)
            yield FootageFrame(index, stamp_ns, f'{name} frame {index}', image, encoding)


class DeviceSource:
    """A live capture device (or anything else OpenCV opens), stamped on arrival.

    Args:
        device: A device index (``'0'``), a device path (``'/dev/video2'``), a URL or a
            video file.
        clock_ns: The clock read after each grab, ns (default: the host's UTC time).

    Raises:
        FootageError: OpenCV cannot open the device or read a frame from it.
    """

    kind = 'device'

    def __init__(self, device: str | int, clock_ns: Callable[[], int] = time.time_ns):
        text = str(device).strip()
        self.name = f'video device {text}'
        self._clock = clock_ns
        self._reader = CaptureReader(int(text) if text.isdigit() else text, self.name)
        self.total: int | None = None

    def __iter__(self) -> Iterator[FootageFrame]:
        """Yields frames as the device delivers them, until it stops."""
        stamps: list[int] = []

        def stamp(_: int) -> None:
            stamps.append(self._clock())

        for index, pixels in enumerate(self._reader.frames(on_grab=stamp)):
            image, encoding = decoded_file_pixels(pixels)
            yield FootageFrame(index, stamps[-1], f'{self.name} frame {index}', image, encoding)

    def close(self) -> None:
        """Stops capturing."""
        self._reader.close()
