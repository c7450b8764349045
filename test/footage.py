"""Footage for the source tests, written the ways a lab writes it (shared by test modules)."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np
import yaml

from lumpbeam_ros.core.vision.camera_model import CameraInfo

#: ROS Bayer pattern -> the colour of the 2 x 2 block's pixels, row by row.
PATTERNS = {'bayer_rggb8': 'RGGB', 'bayer_bggr8': 'BGGR', 'bayer_gbrg8': 'GBRG',
            'bayer_grbg8': 'GRBG'}  # fmt: skip
#: An uncorrected sensor's response to a grey scene, per colour.
GAINS = {'R': 0.55, 'G': 1.0, 'B': 0.75}


def mosaic(channels: dict[str, np.ndarray], encoding: str) -> np.ndarray:
    """Samples full colour planes through a Bayer filter, written here from the ROS names."""
    pattern = PATTERNS[encoding]
    some = next(iter(channels.values()))
    raw = np.empty(some.shape, dtype=np.uint8)
    for k, colour in enumerate(pattern):
        row, col = divmod(k, 2)
        raw[row::2, col::2] = channels[colour][row::2, col::2]
    return raw


def grey_scene_mosaic(mono: np.ndarray, encoding: str) -> np.ndarray:
    """A grey scene seen by a Bayer sensor whose colours respond with :data:`GAINS`."""
    planes = {c: np.clip(np.rint(mono * g), 0, 255).astype(np.uint8) for c, g in GAINS.items()}
    return mosaic(planes, encoding)


def write_calibration(
    path: Path,
    info: CameraInfo,
    model: str | None = 'plumb_bob',
    k: list[float] | None = None,
) -> Path:
    """Writes a calibration as the ROS camera calibrator does (its keys, its layout)."""
    data = {
        'image_width': info.width,
        'image_height': info.height,
        'camera_name': 'tip_camera',
        'camera_matrix': {'rows': 3, 'cols': 3,
                          'data': k if k is not None else info.k.ravel().tolist()},
        'distortion_model': model,
        'distortion_coefficients': {'rows': 1, 'cols': 5, 'data': info.d.tolist()},
        'rectification_matrix': {'rows': 3, 'cols': 3, 'data': np.eye(3).ravel().tolist()},
        'projection_matrix': {
            'rows': 3, 'cols': 4,
            'data': np.hstack([info.k, np.zeros((3, 1))]).ravel().tolist(),
        },
    }  # fmt: skip
    if model is None:
        del data['distortion_model']
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def write_video(path: Path, images: list[np.ndarray], fourcc: str, fps: float = 30.0) -> Path:
    """Writes grey frames with OpenCV's writer."""
    height, width = images[0].shape[:2]
    writer = cv2.VideoWriter(str(path), cv2.VideoWriter_fourcc(*fourcc), fps, (width, height))
    assert writer.isOpened(), fourcc
    for image in images:
        writer.write(cv2.cvtColor(image, cv2.COLOR_GRAY2BGR))
    writer.release()
    return path


def write_timestamps(path: Path, stamps_ns: list[int]) -> Path:
    """One stamp per line, seconds, to the nanosecond."""
    lines = [f'{ns // 1_000_000_000}.{ns % 1_000_000_000:09d}' for ns in stamps_ns]
    path.write_text('# stamps of the frames, s\n' + '\n'.join(lines) + '\n')
    return path
