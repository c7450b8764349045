"""Camera frames for synthetic bags: what the tip camera films during the drop test.

``lumpbeam synth --images`` adds ``/camera/image_raw`` (mono8) and ``/camera/camera_info``
to the drop-test bag, one frame per pose sample with the pose's stamp. Frames are rendered
and written one at a time (a 12 s bag at 2048 x 2048 holds 8.6 GB of pixels), so memory
stays at one frame whatever the duration.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import CAMERA_FRAME, CAMERA_INFO, IMAGE
from lumpbeam_ros.core.bagio import BagWriter
from lumpbeam_ros.core.model.trajectory import TipTrajectory
from lumpbeam_ros.core.vision.config import CameraConfig, load_camera_config
from lumpbeam_ros.core.vision.messages import camera_info_to_data
from lumpbeam_ros.core.vision.synthetic import SyntheticCamera, SyntheticFrame

IMAGE_TOPIC = IMAGE
CAMERA_INFO_TOPIC = CAMERA_INFO
#: ``header.frame_id`` of the images and the camera info.

#: Smallest image side the camera configuration accepts, px.
MIN_SIDE_PX = 64
#: Largest frame rendered, px: rendering holds about 45 bytes a pixel (0.75 GB at this size).
MAX_PIXELS = 4096 * 4096


@dataclass(frozen=True)
class ImageOptions:
    """How the synthetic camera films.

    Attributes:
        width: Image width, px (the focal length scales with it: same view).
        height: Image height, px.
        camera_config: Camera parameter file; ``None`` takes ``config/camera.yaml``.
        seed: Noise seed; ``None`` takes the file's ``synthetic.seed``.
    """

    width: int = 2048
    height: int = 2048
    camera_config: str | Path | None = None
    seed: int | None = None

    def __post_init__(self) -> None:
        if min(self.width, self.height) < MIN_SIDE_PX:
            raise LumpbeamError(
                f'image size {self.width}x{self.height}: each side must be at least '
                f'{MIN_SIDE_PX} px'
            )
        if self.width * self.height > MAX_PIXELS:
            raise LumpbeamError(
                f'image size {self.width}x{self.height}: {self.width * self.height} px; the '
                f'limit is {MAX_PIXELS} px (4096x4096), each frame rendered in memory'
            )


def parse_image_size(text: str) -> tuple[int, int]:
    """Parses ``WxH`` (e.g. ``1024x1024``) for ``--image-size``.

    Raises:
        LumpbeamError: Not two positive integers joined by ``x``, a side below 64 px, or
            more than :data:`MAX_PIXELS`.
    """
    match = re.fullmatch(r'\s*(\d+)\s*[xX]\s*(\d+)\s*', text)
    if match is None:
        raise LumpbeamError(f'--image-size {text!r}: expected WIDTHxHEIGHT, e.g. 1024x1024')
    width, height = int(match.group(1)), int(match.group(2))
    if min(width, height) < MIN_SIDE_PX:
        raise LumpbeamError(f'--image-size {text!r}: each side must be at least {MIN_SIDE_PX} px')
    ImageOptions(width, height)  # refuses a frame too large to render
    return width, height


class ImageStream:
    """Renders a trajectory's frames in order and writes each into a bag on demand.

    Args:
        trajectory: What the camera films (the measured motion: effects such as a sensor
            latency are already in it); one frame per sample, stamped with its time.
        options: Size, camera file and seed.
        config: The camera configuration to film with, in place of ``options``' file (an
            arm's, its board placed for the arm).

    Raises:
        ConfigError: A bad camera file.
        LumpbeamError: A trajectory the camera cannot render (too short, not finite).
    """

    def __init__(
        self,
        trajectory: TipTrajectory,
        options: ImageOptions,
        config: CameraConfig | None = None,
    ):
        if config is None:
            config = load_camera_config(options.camera_config)
        self.config = config.with_resolution(options.width, options.height)
        camera = SyntheticCamera(self.config, options.seed)
        self._info = camera_info_to_data(self.config.camera_info, CAMERA_FRAME)
        self._frames: Iterator[SyntheticFrame] = camera.render_trajectory(
            trajectory.t, trajectory.x, trajectory.z, trajectory.pitch
        )
        self.written = 0

    def write_next(self, bag: BagWriter) -> SyntheticFrame:
        """Renders the next frame and writes it with its camera info (same stamp).

        A driver publishes the camera info beside every frame; so does this, so a reader
        may start anywhere in the bag.

        Args:
            bag: The open bag.

        Returns:
            The frame written.

        Raises:
            LumpbeamError: Every sample has been written already.
            BagError: The bag cannot be written.
        """
        frame = next(self._frames, None)
        if frame is None:
            raise LumpbeamError(f'image stream: all {self.written} frames are written')
        bag.write_camera_info(CAMERA_INFO_TOPIC, frame.stamp, self._info)
        bag.write_image(IMAGE_TOPIC, frame.stamp, frame.image, CAMERA_FRAME, 'mono8')
        self.written += 1
        return frame
