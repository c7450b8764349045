"""Real photographs through ``lumpbeam track``, against plain OpenCV's poses of them.

The set (``test/data/real_photos``, its README says where it comes from) is OpenCV's stereo
sample: 13 pairs of 640 x 480 photographs of a 9 x 6 board held by hand, from two cameras
whose lenses have k1 near -0.27. Each camera's folder goes through the command as a user
runs it (``--pose-model free``, its ROS calibration file); the poses are read back from OUT
with rosbags, and set against what plain OpenCV gives: ``findChessboardCorners``,
``cornerSubPix`` and ``solvePnP`` (``SOLVEPNP_ITERATIVE``) with the same calibration.

``python test/core/vision/real_photos.py`` prints the figures the tests check.
"""

from __future__ import annotations

import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np
from rosbags.highlevel import AnyReader

from lumpbeam_ros.apps.cli.main import main as lumpbeam
from lumpbeam_ros.core.vision.camera_info_file import read_camera_info_file
from lumpbeam_ros.core.vision.camera_model import CameraInfo
from lumpbeam_ros.core.vision.config import (
    CameraConfig,
    load_camera_config,
    parse_board,
    with_board,
)
from lumpbeam_ros.core.vision.geometry import Transform

#: The set, with ``left/``, ``right/``, ``left.yaml`` and ``right.yaml``.
PHOTOS = Path(__file__).resolve().parents[2] / 'data' / 'real_photos'

CAMERAS = ('left', 'right')

#: Inner corners ``(per row, rows)`` and the square (the set does not say; see its README).
BOARD = '9x6'
PATTERN = (9, 6)
SQUARE_M = 0.025

#: ``cornerSubPix`` of the reference: an 11 x 11 px window, 30 iterations, 0.001 px. (The
#: (11, 11) half-size of OpenCV's tutorial pulls corner 26 of right02.jpg 5 px off.)
SUBPIX_WINDOW = (5, 5)
SUBPIX_CRITERIA = (cv2.TERM_CRITERIA_EPS | cv2.TERM_CRITERIA_MAX_ITER, 30, 0.001)


@dataclass(frozen=True)
class View:
    """One photograph: plain OpenCV's pose of the board and the product's.

    Attributes:
        name: File name (``left01.jpg``).
        opencv: ``T_camera_board`` from plain OpenCV (board frame: the product's, origin at
            the centre of the squares), or ``None`` when OpenCV does not find the board.
        product: ``T_camera_board`` from ``lumpbeam track``'s ``/tip_pose``, or ``None``.
        sigma: OpenCV's own standard deviations of ``opencv`` (translation m x 3, rotation
            rad x 3) from its reprojection residuals, or ``None``.
        corner_rms_px: RMS reprojection error of OpenCV's fit, px (NaN without one).
        labelling_gap_px: :func:`labelling_gap` (NaN without both poses).
    """

    name: str
    opencv: Transform | None
    product: Transform | None
    sigma: np.ndarray | None
    corner_rms_px: float
    labelling_gap_px: float


def config() -> CameraConfig:
    """The package's configuration with the set's board, as ``--board`` and ``--square-m``."""
    return with_board(load_camera_config(), parse_board(BOARD), SQUARE_M)


def calibration(camera: str) -> CameraInfo:
    """The camera's ROS calibration file."""
    return read_camera_info_file(PHOTOS / f'{camera}.yaml')


def photographs(camera: str) -> list[Path]:
    """The camera's photographs in name order (the order ``lumpbeam track`` takes them)."""
    return sorted((PHOTOS / camera).glob('*.jpg'))


def track(camera: str, out: Path) -> dict[int, Transform]:
    """Runs ``lumpbeam track`` on the camera's folder; its poses by frame index.

    With ``--fps 1`` frame ``i`` is stamped ``i`` s. The poses (the tip's in ``beam_base``)
    become ``T_camera_board`` through the configured rig, as the frames are documented.
    """
    code = lumpbeam(
        [
            'track', str(PHOTOS / camera), str(out), '--camera-info',
            str(PHOTOS / f'{camera}.yaml'), '--board', BOARD, '--square-m', str(SQUARE_M),
            '--pose-model', 'free', '--fps', '1', '--quiet',
        ]
    )  # fmt: skip
    if code != 0:
        raise RuntimeError(f'lumpbeam track {camera} exited {code}')
    rig = config().rig
    poses = {}
    with AnyReader([out]) as bag:
        connections = [c for c in bag.connections if c.topic == '/tip_pose']
        for connection, _, raw in bag.messages(connections=connections):
            message = bag.deserialize(raw, connection.msgtype)
            stamp = message.header.stamp
            index = round(stamp.sec + stamp.nanosec * 1e-9)
            p, q = message.pose.position, message.pose.orientation
            rotation = _quaternion_matrix(q.x, q.y, q.z, q.w)
            base_tip = Transform(rotation, np.array([p.x, p.y, p.z]))
            poses[index] = rig.tip_camera.inverse() @ base_tip.inverse() @ rig.base_board
    return poses


def _quaternion_matrix(x: float, y: float, z: float, w: float) -> np.ndarray:
    return np.asarray(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def opencv_corners(gray: np.ndarray) -> np.ndarray | None:
    """Plain OpenCV's corners (N x 2, its own order), or ``None`` when it finds no board."""
    found, corners = cv2.findChessboardCorners(gray, PATTERN, None)
    if not found:
        return None
    refined = cv2.cornerSubPix(gray, corners, SUBPIX_WINDOW, (-1, -1), SUBPIX_CRITERIA)
    return np.asarray(refined, dtype=np.float64).reshape(-1, 2)


def labelling_gap(
    corners: np.ndarray, object_points: np.ndarray, camera_board: Transform, info: CameraInfo
) -> float:
    """How far OpenCV's corners are from the product's pose's projection, label by label, px.

    OpenCV labels this board by its colours (corner 0 has a dark square on its ``(+x, +y)``
    side, as in the product's board), so a pose of the product that labels the board as
    OpenCV does projects every corner onto OpenCV's corner of the same index; one turned
    by 180 degrees or mirrored misses by squares.
    """
    projected = info.project(camera_board.apply(object_points))
    return float(np.max(np.linalg.norm(projected - corners, axis=1)))


def opencv_pose(
    corners: np.ndarray, object_points: np.ndarray, info: CameraInfo
) -> tuple[Transform, np.ndarray, float]:
    """``solvePnP`` (iterative) on corners in board order, with its standard deviations.

    The deviations are ``s^2 (J^T J)^-1`` of OpenCV's own projection Jacobian (rvec, tvec),
    ``s`` the residual RMS with ``2N - 6`` degrees of freedom; the rotation's are those of
    the rotation vector, near enough to angles about the camera's axes at these sizes.
    """
    obj = object_points.astype(np.float64)
    ok, rvec, tvec = cv2.solvePnP(obj, corners, info.k, info.d, flags=cv2.SOLVEPNP_ITERATIVE)
    assert ok
    projected, jacobian = cv2.projectPoints(obj, rvec, tvec, info.k, info.d)
    residual = projected.reshape(-1, 2) - corners
    dof = residual.size - 6
    variance = float(np.sum(residual**2)) / dof
    j = jacobian[:, :6]
    covariance = np.linalg.inv(j.T @ j) * variance
    sigma = np.sqrt(np.diag(covariance))
    transform = Transform(cv2.Rodrigues(rvec)[0], tvec.ravel())
    return transform, np.concatenate([sigma[3:], sigma[:3]]), float(np.sqrt(variance))


def views(out_root: Path) -> dict[str, list[View]]:
    """Every photograph of both cameras through ``lumpbeam track`` and plain OpenCV."""
    board = config().rig.board
    object_points = board.object_points()
    result = {}
    for camera in CAMERAS:
        info = calibration(camera)
        poses = track(camera, out_root / camera)
        rows = []
        for index, path in enumerate(photographs(camera)):
            gray = cv2.imread(str(path), cv2.IMREAD_GRAYSCALE)
            corners = opencv_corners(gray)
            product = poses.get(index)
            reference, sigma, rms, gap = None, None, float('nan'), float('nan')
            if corners is not None:
                # OpenCV's own labels: its row-major order is the product's board order.
                reference, sigma, rms = opencv_pose(corners, object_points, info)
                if product is not None:
                    gap = labelling_gap(corners, object_points, product, info)
            rows.append(View(path.name, reference, product, sigma, rms, gap))
        result[camera] = rows
    return result


def pose_difference(a: Transform, b: Transform) -> tuple[np.ndarray, float]:
    """Translation difference (m, 3) and rotation angle between two poses (rad)."""
    relative = a.rotation.T @ b.rotation
    angle = float(np.arccos(np.clip((np.trace(relative) - 1) / 2, -1.0, 1.0)))
    return b.translation - a.translation, angle


def rig_spread(left: list[Transform], right: list[Transform]) -> tuple[float, float]:
    """How much the left-right relative pose moves over the pairs.

    Each pair gives ``T_left_right = T_left_board T_right_board^-1``; a fixed rig gives the
    same one every time, so its scatter is the measurement's.

    Returns:
        The RMS distance of the pairs' baselines from their mean, m, and the RMS angle of
        their rotations from the first pair's turned to their mean, rad.
    """
    relatives = [a @ b.inverse() for a, b in zip(left, right, strict=True)]
    translations = np.array([r.translation for r in relatives])
    spread_t = float(np.sqrt(np.mean(np.sum((translations - translations.mean(0)) ** 2, 1))))
    # The chordal mean: the rotation nearest the average matrix.
    u, _, vt = np.linalg.svd(np.mean([r.rotation for r in relatives], axis=0))
    mean = u @ np.diag([1.0, 1.0, np.linalg.det(u @ vt)]) @ vt
    angles = [pose_difference(Transform(mean, np.zeros(3)), r)[1] for r in relatives]
    return spread_t, float(np.sqrt(np.mean(np.square(angles))))


def report(out_root: Path) -> list[str]:
    """The figures, one line each."""
    table = views(out_root)
    lines = []
    for camera, rows in table.items():
        found = sum(v.opencv is not None for v in rows)
        posed = sum(v.product is not None for v in rows)
        lines.append(f'{camera}: {len(rows)} photographs, OpenCV finds {found}, poses {posed}')
        for v in rows:
            if v.opencv is None or v.product is None or v.sigma is None:
                continue
            dt, angle = pose_difference(v.opencv, v.product)
            lines.append(
                f'  {v.name}: |dt| {np.linalg.norm(dt) * 1e3:.3f} mm (OpenCV sigma '
                f'{np.linalg.norm(v.sigma[:3]) * 1e3:.3f}), angle {angle * 1e3:.3f} mrad '
                f'(sigma {np.linalg.norm(v.sigma[3:]) * 1e3:.3f}), OpenCV rms '
                f'{v.corner_rms_px:.3f} px, labels {v.labelling_gap_px:.2f} px apart'
            )
    pairs = [
        (a, b)
        for a, b in zip(table['left'], table['right'], strict=True)
        if a.product is not None and b.product is not None and a.opencv and b.opencv
    ]
    for label, pick in (('product', lambda v: v.product), ('OpenCV', lambda v: v.opencv)):
        t, r = rig_spread([pick(a) for a, _ in pairs], [pick(b) for _, b in pairs])
        lines.append(
            f'rig over {len(pairs)} pairs, {label}: baseline spread {t * 1e3:.3f} mm, '
            f'rotation spread {r * 1e3:.3f} mrad'
        )
    return lines


if __name__ == '__main__':
    with tempfile.TemporaryDirectory() as folder:
        print('\n'.join(report(Path(folder))))
    sys.exit(0)
