"""Frames from a folder of image files, in the order of their names."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import cv2

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.vision.sources.frame import FootageFrame
from lumpbeam_ros.core.vision.sources.pixels import decoded_file_pixels
from lumpbeam_ros.core.vision.sources.stamps import FootageError, FrameStamps

#: File name endings read as images (case-insensitive); other files are ignored.
IMAGE_SUFFIXES = ('.png', '.jpg', '.jpeg', '.tif', '.tiff', '.bmp', '.pgm', '.ppm', '.pnm')


class FolderSource:
    """The images of a folder, sorted by file name (zero-pad the numbers: ``0009.png``).

    A file that does not decode gives a frame without pixels (a lost frame), not the end.

    Args:
        folder: The folder.
        stamps: Stamp of each image, in name order.

    Raises:
        FootageError: Not a folder, no image file in it, or fewer stamps than images.
    """

    kind = 'folder'

    def __init__(self, folder: str | Path, stamps: FrameStamps):
        self.path = Path(folder)
        if not self.path.is_dir():
            raise FootageError(f'{self.path}: no such folder')
        self.files = sorted(
            (p for p in self.path.iterdir() if p.is_file() and p.suffix.lower() in IMAGE_SUFFIXES),
            key=lambda p: p.name,
        )
        if not self.files:
            raise FootageError(
                f'{self.path}: no image files ({", ".join(IMAGE_SUFFIXES)}) in the folder'
            )
        stamps.check_covers(len(self.files), str(self.path))
        self.stamps = stamps
        self.total: int | None = len(self.files)

    def __iter__(self) -> Iterator[FootageFrame]:
        """Yields one frame per image file."""
        for index, file in enumerate(self.files):
            stamp_ns = self.stamps.ns(index, str(self.path))
            pixels = cv2.imread(str(file), cv2.IMREAD_UNCHANGED)
            if pixels is None:
                yield FootageFrame(index, stamp_ns, str(file), None, problem='cannot decode')
                continue
            try:
                image, encoding = decoded_file_pixels(pixels)
            except LumpbeamError as exc:
                yield FootageFrame(index, stamp_ns, str(file), None, problem=str(exc))
                continue
            yield FootageFrame(index, stamp_ns, str(file), image, encoding)
