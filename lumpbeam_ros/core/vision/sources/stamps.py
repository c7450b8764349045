"""When each frame of a video or an image folder was exposed.

A video file or a folder of images carries no usable clock, so the stamps come from the
user: a frame rate (``t_i = t0 + i / fps``) or a timestamps file, one stamp per frame.

Timestamps file: plain text, one stamp per line in seconds (decimal, e.g. ``12.005`` or
``1732000000.123456789``; read exactly to the nanosecond), in frame order, strictly
increasing; blank lines and lines starting with ``#`` are skipped. Extra stamps after the
last frame are ignored; fewer stamps than frames is an error.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from decimal import Decimal, InvalidOperation
from pathlib import Path

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.bagio.convert import NS_PER_S, seconds_to_ns


class FootageError(LumpbeamError):
    """A video, an image folder, its stamps or its calibration cannot be used."""


@dataclass(frozen=True)
class FrameStamps:
    """The stamp of every frame.

    Use :meth:`from_fps` or :meth:`from_file`.

    Attributes:
        source: How the stamps were given, for messages (``'--fps 180'``, a file name).
        start_ns: Stamp of frame 0 with a frame rate, ns.
        fps: Frames per second, or ``None`` with a list of stamps.
        listed_ns: The stamps of a file, ns, or ``None`` with a frame rate.
    """

    source: str
    start_ns: int = 0
    fps: float | None = None
    listed_ns: tuple[int, ...] | None = None

    @staticmethod
    def from_fps(fps: float, start_s: float = 0.0) -> FrameStamps:
        """Stamps at a constant rate: ``t_i = start_s + i / fps``.

        Raises:
            FootageError: A rate that is not a positive finite number, or a negative start.
        """
        if not (isinstance(fps, int | float) and math.isfinite(fps) and fps > 0):
            raise FootageError(f'frame rate must be a positive number, got {fps!r}')
        if not (math.isfinite(start_s) and start_s >= 0):
            raise FootageError(f'start time must be a finite number >= 0 s, got {start_s!r}')
        return FrameStamps(f'--fps {fps:g}', start_ns=seconds_to_ns(start_s), fps=float(fps))

    @staticmethod
    def from_file(path: str | Path) -> FrameStamps:
        """Reads a timestamps file (format in this module's description).

        Raises:
            FootageError: Missing file, a line that is not a number, a negative stamp,
                stamps not strictly increasing, or no stamp at all.
        """
        path = Path(path)
        try:
            lines = path.read_text().splitlines()
        except (OSError, UnicodeDecodeError) as exc:
            raise FootageError(f'{path}: cannot read the timestamps file ({exc})') from None
        stamps: list[int] = []
        for number, line in enumerate(lines, start=1):
            text = line.strip()
            if not text or text.startswith('#'):
                continue
            try:
                seconds = Decimal(text)
            except InvalidOperation:
                raise FootageError(f'{path}:{number}: {text!r} is not a time in seconds') from None
            if not seconds.is_finite() or seconds < 0:
                raise FootageError(f'{path}:{number}: stamp {text} must be finite and >= 0')
            ns = int((seconds * NS_PER_S).to_integral_value())
            if stamps and ns <= stamps[-1]:
                raise FootageError(f'{path}:{number}: stamp {text} does not increase')
            stamps.append(ns)
        if not stamps:
            raise FootageError(f'{path}: the timestamps file holds no stamp')
        return FrameStamps(str(path), listed_ns=tuple(stamps))

    @property
    def count(self) -> int | None:
        """How many frames have a stamp (``None``: any number)."""
        return None if self.listed_ns is None else len(self.listed_ns)

    def check_covers(self, frames: int, footage: str) -> None:
        """Checks that every one of ``frames`` frames has a stamp.

        Raises:
            FootageError: Fewer stamps than frames.
        """
        if self.count is not None and frames > self.count:
            raise FootageError(
                f'{self.source} has {self.count} stamps but {footage} has {frames} frames'
            )

    def ns(self, index: int, footage: str) -> int:
        """The stamp of frame ``index``, ns.

        Args:
            index: Frame number, from 0.
            footage: The video or folder, for the message.

        Raises:
            FootageError: The timestamps file ends before this frame.
        """
        if self.listed_ns is not None:
            if index >= len(self.listed_ns):
                raise FootageError(
                    f'{self.source} has {len(self.listed_ns)} stamps but {footage} has more frames'
                )
            return self.listed_ns[index]
        assert self.fps is not None
        return self.start_ns + round(index * NS_PER_S / self.fps)
