"""The ROS camera calibration file: what the ROS calibrator writes and camera_info_manager reads.

The YAML format of ``camera_calibration_parsers``::

    image_width: 640
    image_height: 480
    camera_name: tip_camera
    camera_matrix: {rows: 3, cols: 3, data: [fx, 0, cx, 0, fy, cy, 0, 0, 1]}
    distortion_model: plumb_bob
    distortion_coefficients: {rows: 1, cols: 5, data: [k1, k2, p1, p2, k3]}
    rectification_matrix: {rows: 3, cols: 3, data: [1, 0, 0, 0, 1, 0, 0, 0, 1]}
    projection_matrix: {rows: 3, cols: 4, data: [fx', 0, cx', 0, 0, fy', cy', 0, 0, 0, 1, 0]}

``image_width``, ``image_height``, ``camera_matrix`` and ``distortion_coefficients`` are
required. As in ``camera_calibration_parsers``, a missing ``distortion_model`` means
plumb_bob and a missing ``camera_name`` is ``unknown``; the rectification and projection
matrices, when present, must be 3x3 and 3x4 (a monocular camera's raw image is tracked with
K and D; they are not used). The model name and coefficients go to
:class:`~lumpbeam_ros.core.vision.camera_model.CameraInfo` as they are, and it refuses what it does
not support.

A ``camera_info_url`` as camera_info_manager takes it is ``file:///absolute/path.yaml``; a
plain path is taken too.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any
from urllib.parse import unquote, urlparse

import numpy as np
import yaml

from lumpbeam_ros.base.errors import ConfigError, LumpbeamError
from lumpbeam_ros.core.vision.camera_model import CameraInfo


def _matrix(
    doc: dict[str, Any], key: str, shape: tuple[int, int] | None, source: Path
) -> np.ndarray:
    node = doc.get(key)
    if not isinstance(node, dict) or not {'rows', 'cols', 'data'} <= set(node):
        raise ConfigError(source, key, 'must be a mapping with rows, cols and data')
    rows, cols, data = node['rows'], node['cols'], node['data']
    if not (isinstance(rows, int) and isinstance(cols, int)) or rows < 1 or cols < 0:
        raise ConfigError(source, key, f'rows and cols must be integers, got {rows!r}, {cols!r}')
    if shape is not None and (rows, cols) != shape:
        raise ConfigError(source, key, f'must be {shape[0]} x {shape[1]}, got {rows} x {cols}')
    if (
        not isinstance(data, list)
        or len(data) != rows * cols
        or any(isinstance(v, bool) or not isinstance(v, int | float) for v in data)
    ):
        raise ConfigError(source, key, f'data must be {rows * cols} numbers, got {data!r}')
    return np.asarray(data, dtype=float).reshape(rows, cols)


def _size(doc: dict[str, Any], key: str, source: Path) -> int:
    value = doc.get(key)
    if isinstance(value, bool) or not isinstance(value, int) or value <= 0:
        raise ConfigError(source, key, f'must be a positive integer, got {value!r}')
    return value


def read_camera_info_file(path: str | Path) -> CameraInfo:
    """Reads a ROS camera calibration YAML file.

    Args:
        path: The file.

    Returns:
        The intrinsics.

    Raises:
        ConfigError: A missing or unreadable file, a missing or malformed key, or
            intrinsics the camera model refuses (K of zeros, an unsupported distortion
            model); the message names the file.
    """
    source = Path(path)
    try:
        doc = yaml.safe_load(source.read_text())
    except OSError as exc:
        problem = f'cannot read the calibration file ({exc.strerror})'
        raise ConfigError(source, '', problem) from None
    except yaml.YAMLError as exc:
        problem = str(exc).splitlines()[0]
        raise ConfigError(source, '', f'not a YAML calibration file ({problem})') from None
    if not isinstance(doc, dict):
        raise ConfigError(source, '', 'not a camera calibration file (no image_width, ...)')
    width = _size(doc, 'image_width', source)
    height = _size(doc, 'image_height', source)
    k = _matrix(doc, 'camera_matrix', (3, 3), source)
    d = _matrix(doc, 'distortion_coefficients', None, source).ravel()
    for key, shape in (('rectification_matrix', (3, 3)), ('projection_matrix', (3, 4))):
        if key in doc:
            _matrix(doc, key, shape, source)
    model = doc.get('distortion_model', 'plumb_bob')
    if not isinstance(model, str):
        raise ConfigError(source, 'distortion_model', f'must be a name, got {model!r}')
    try:
        return CameraInfo(width, height, k, d, model)
    except LumpbeamError as exc:
        raise ConfigError(source, '', str(exc)) from None


def camera_info_from_url(url: str) -> CameraInfo:
    """Reads the calibration a ``camera_info_url`` points at.

    Args:
        url: ``file:///path/to/camera.yaml`` (camera_info_manager's form) or a plain path.

    Returns:
        The intrinsics.

    Raises:
        ConfigError: Another URL scheme (``package://``, ``http://``), or what
            :func:`read_camera_info_file` raises.
    """
    parsed = urlparse(url)
    if parsed.scheme == 'file':
        if parsed.netloc not in ('', 'localhost'):
            raise ConfigError(url, '', 'a file:// URL needs an absolute path (file:///...)')
        return read_camera_info_file(unquote(parsed.path))
    if parsed.scheme:
        raise ConfigError(url, '', f'unsupported URL scheme {parsed.scheme}:// (use file://)')
    return read_camera_info_file(url)
