"""One frame read from footage (a video, an image folder, a capture device)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lumpbeam_ros.core.bagio.convert import ns_to_seconds


@dataclass(frozen=True)
class FootageFrame:
    """A frame and when it was exposed.

    Attributes:
        index: Frame number in the footage, from 0.
        stamp_ns: Exposure stamp, ns.
        label: Where it came from, for messages (``'clip.avi frame 12'``, an image's path).
        pixels: Tracker-ready pixels (see ``encoding``), or ``None`` when the frame could not
            be decoded.
        encoding: ``'mono8'``, ``'bgr8'`` or ``'rgb8'``.
        problem: Why ``pixels`` is ``None`` (empty otherwise).
    """

    index: int
    stamp_ns: int
    label: str
    pixels: np.ndarray | None
    encoding: str = 'mono8'
    problem: str = ''

    @property
    def stamp(self) -> float:
        """The stamp in seconds (what the tracker works with)."""
        return ns_to_seconds(self.stamp_ns)
