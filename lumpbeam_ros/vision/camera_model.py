"""The pinhole camera with plumb_bob distortion, as ``sensor_msgs/CameraInfo`` describes it."""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import cv2
import numpy as np

from lumpbeam_ros.errors import LumpbeamError

#: The only distortion model handled (ROS ``plumb_bob``: k1, k2, p1, p2, k3).
PLUMB_BOB = 'plumb_bob'


@dataclass(frozen=True)
class CameraInfo:
    """The calibration a camera driver publishes, without ROS types.

    Attributes:
        width: Image width, px.
        height: Image height, px.
        k: 3x3 intrinsic matrix (fx, fy, cx, cy; pixel centres at integers).
        d: Distortion coefficients ``k1, k2, p1, p2, k3``.
        distortion_model: ``'plumb_bob'``.
    """

    width: int
    height: int
    k: np.ndarray
    d: np.ndarray = field(default_factory=lambda: np.zeros(5))
    distortion_model: str = PLUMB_BOB

    def __post_init__(self) -> None:
        k = np.asarray(self.k, dtype=float)
        d = np.asarray(self.d, dtype=float).ravel()
        if self.width <= 0 or self.height <= 0:
            raise LumpbeamError(f'camera info: bad image size {self.width} x {self.height}')
        if k.shape != (3, 3) or not np.all(np.isfinite(k)) or k[0, 0] <= 0 or k[1, 1] <= 0:
            raise LumpbeamError('camera info: K must be a finite 3x3 matrix with fx, fy > 0')
        if (
            self.distortion_model != PLUMB_BOB
            or d.size not in (0, 5)
            or not np.all(np.isfinite(d))
        ):
            raise LumpbeamError(
                f'camera info: need plumb_bob with 5 finite coefficients, got '
                f'{self.distortion_model!r} with {d.size}'
            )
        object.__setattr__(self, 'k', k)
        object.__setattr__(self, 'd', np.zeros(5) if d.size == 0 else d)

    @staticmethod
    def pinhole(
        width: int,
        height: int,
        focal_px: float,
        centre_offset_px: tuple[float, float] = (0.0, 0.0),
        distortion: tuple[float, ...] = (0.0, 0.0, 0.0, 0.0, 0.0),
    ) -> CameraInfo:
        """Builds square-pixel intrinsics with the principal point near the image centre.

        Args:
            width: Image width, px.
            height: Image height, px.
            focal_px: fx = fy, px.
            centre_offset_px: Principal point minus the image centre ``((w-1)/2, (h-1)/2)``.
            distortion: ``k1, k2, p1, p2, k3``.

        Returns:
            The camera info.
        """
        cx = (width - 1) / 2.0 + centre_offset_px[0]
        cy = (height - 1) / 2.0 + centre_offset_px[1]
        k = np.array([[focal_px, 0.0, cx], [0.0, focal_px, cy], [0.0, 0.0, 1.0]])
        return CameraInfo(int(width), int(height), k, np.asarray(distortion, dtype=float))

    @property
    def has_distortion(self) -> bool:
        """Whether any distortion coefficient is non-zero."""
        return bool(np.any(self.d != 0.0))

    def scaled(self, width: int, height: int) -> CameraInfo:
        """Returns the same lens on a sensor of another size, focal length scaled with width.

        Args:
            width: New width, px.
            height: New height, px.

        Returns:
            Intrinsics whose field of view across the width is unchanged.
        """
        s = width / self.width
        offset = (
            self.k[0, 2] - (self.width - 1) / 2.0,
            self.k[1, 2] - (self.height - 1) / 2.0,
        )
        return replace(
            CameraInfo.pinhole(width, height, self.k[0, 0] * s, (offset[0] * s, offset[1] * s)),
            d=self.d.copy(),
        )

    def project(self, points: np.ndarray) -> np.ndarray:
        """Projects camera-frame points (N x 3, z forward) to distorted pixels (N x 2).

        Args:
            points: Points in the camera optical frame, m; z must be positive.

        Returns:
            Pixel coordinates.
        """
        xy = points[:, :2] / points[:, 2:3]
        if self.has_distortion:
            k1, k2, p1, p2, k3 = self.d
            x, y = xy[:, 0], xy[:, 1]
            r2 = x * x + y * y
            radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
            xy = np.column_stack(
                [
                    x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
                    y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y,
                ]
            )
        return xy * np.diag(self.k)[:2] + self.k[:2, 2]

    def undistort_pixels(self, pixels: np.ndarray) -> np.ndarray:
        """Maps measured (distorted) pixels to where an ideal pinhole camera sees them.

        Args:
            pixels: N x 2 pixel coordinates.

        Returns:
            N x 2 ideal pinhole pixel coordinates (the identity without distortion).
        """
        if not self.has_distortion:
            return np.asarray(pixels, dtype=float)
        pts = np.ascontiguousarray(pixels, dtype=np.float64).reshape(-1, 1, 2)
        criteria = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 20, 1e-10)
        ideal = cv2.undistortPoints(pts, self.k, self.d, None, None, self.k, criteria)
        return ideal.reshape(-1, 2)

    def pinhole_only(self) -> CameraInfo:
        """Returns the same intrinsics without distortion."""
        return replace(self, d=np.zeros(5))
