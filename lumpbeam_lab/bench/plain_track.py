"""The plain script a user would write to track a bag: the baseline of ``lumpbeam track``.

It reads the camera's images with the product's bag reader, tracks each with its
:class:`~lumpbeam_ros.core.vision.session.TrackingSession` and keeps the poses in memory,
one frame after the other: no copy of the other topics, no output bag, no truth comparison.
``python -m lumpbeam_lab.bench.plain_track BAG WIDTH HEIGHT`` prints the poses it got.
"""

from __future__ import annotations

import sys
from pathlib import Path


def track(bag: Path, width: int, height: int) -> int:
    """Tracks ``/camera/image_raw`` of ``bag`` with the default camera at that size.

    Returns:
        The poses tracked.
    """
    from lumpbeam_ros.core.bagio import iter_images
    from lumpbeam_ros.core.vision.config import load_camera_config
    from lumpbeam_ros.core.vision.session import TrackingSession

    config = load_camera_config().with_resolution(width, height)
    session = TrackingSession(config, config.camera_info, 'plane')
    return sum(session.process(f.pixels, f.t, f.encoding).ok for f in iter_images(bag))


if __name__ == '__main__':
    print(track(Path(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])))
