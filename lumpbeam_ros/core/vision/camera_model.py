"""The calibrated camera as ``sensor_msgs/CameraInfo`` describes it: K and a distortion model.

Every step of the tracker goes through two calls of :class:`CameraInfo`: :meth:`project`
(camera-frame points to the real, distorted pixels) and :meth:`undistort_pixels` (real pixels
to where an ideal pinhole camera with the same K sees them). The distortion models are those
of ROS (``image_geometry``) and OpenCV:

* ``plumb_bob``: ``k1, k2, p1, p2, k3`` (Brown-Conrady, OpenCV's default model);
* ``rational_polynomial``: ``k1, k2, p1, p2, k3, k4, k5, k6`` (OpenCV's rational model);
* ``equidistant``: ``k1, k2, k3, k4`` (the fisheye model of ``cv2.fisheye``).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError

PLUMB_BOB = 'plumb_bob'
RATIONAL_POLYNOMIAL = 'rational_polynomial'
EQUIDISTANT = 'equidistant'

#: Supported distortion models and their number of coefficients.
DISTORTION_MODELS = {PLUMB_BOB: 5, RATIONAL_POLYNOMIAL: 8, EQUIDISTANT: 4}

#: The camera matrix OpenCV's undistortion works with here (normalized coordinates in and out).
_EYE = np.eye(3)


#: The widest or tallest image taken, px: past the largest machine-vision sensors (151 MP,
#: 14204 x 10652); a 20000 x 20000 frame is 400 MB a copy, and a mistake.
MAX_IMAGE_SIDE_PX = 16384


def check_image_side(width: int, height: int, what: str) -> None:
    """Refuses an image size past :data:`MAX_IMAGE_SIDE_PX` (or not positive).

    Raises:
        LumpbeamError: The size, in one line.
    """
    if not (0 < width <= MAX_IMAGE_SIDE_PX and 0 < height <= MAX_IMAGE_SIDE_PX):
        raise LumpbeamError(
            f'{what}: bad image size {width} x {height} (each side 1 to {MAX_IMAGE_SIDE_PX} px)'
        )


#: The longest focal length taken, in image sizes: ``f = size / (2 tan(fov / 2))`` is 1000
#: sizes for a field of view of 0.06 degrees, narrower than any lens a rig puts at a tip.
MAX_FOCAL_IMAGES = 1000.0


@dataclass(frozen=True)
class CameraInfo:
    """The calibration a camera driver publishes, without ROS types.

    Attributes:
        width: Image width, px.
        height: Image height, px.
        k: 3x3 intrinsic matrix (fx, fy, cx, cy; pixel centres at integers, ROS's and
            OpenCV's convention).
        d: Distortion coefficients in the order of ``distortion_model``.
        distortion_model: A key of :data:`DISTORTION_MODELS`.
    """

    width: int
    height: int
    k: np.ndarray
    d: np.ndarray = field(default_factory=lambda: np.zeros(5))
    distortion_model: str = PLUMB_BOB

    def __post_init__(self) -> None:
        k = np.asarray(self.k, dtype=float)
        d = np.asarray(self.d, dtype=float).ravel()
        check_image_side(self.width, self.height, 'camera info')
        if k.shape != (3, 3) or not np.all(np.isfinite(k)) or k[0, 0] <= 0 or k[1, 1] <= 0:
            raise LumpbeamError(
                'camera info: K must be a finite 3x3 matrix with fx, fy > 0 (an uncalibrated '
                'camera publishes K = 0)'
            )
        longest = max(self.width, self.height)
        if max(k[0, 0], k[1, 1]) > MAX_FOCAL_IMAGES * longest:
            raise LumpbeamError(
                f'camera info: fx {k[0, 0]:.6g}, fy {k[1, 1]:.6g} px is no lens for a '
                f'{self.width} x {self.height} image (at most {MAX_FOCAL_IMAGES:g} times its '
                'size: a field of view of 0.06 deg; a K scaled by mistake?)'
            )
        size = DISTORTION_MODELS.get(self.distortion_model)
        if size is None:
            raise LumpbeamError(
                f'camera info: distortion model {self.distortion_model!r} is not supported '
                f'(use one of {", ".join(DISTORTION_MODELS)})'
            )
        if d.size not in (0, size) or not np.all(np.isfinite(d)):
            raise LumpbeamError(
                f'camera info: {self.distortion_model} needs {size} finite coefficients, '
                f'got {d.size}'
            )
        object.__setattr__(self, 'k', k)
        object.__setattr__(self, 'd', np.zeros(size) if d.size == 0 else d)

    @staticmethod
    def pinhole(
        width: int,
        height: int,
        focal_px: float,
        centre_offset_px: tuple[float, float] = (0.0, 0.0),
        distortion: tuple[float, ...] = (0.0, 0.0, 0.0, 0.0, 0.0),
        distortion_model: str = PLUMB_BOB,
    ) -> CameraInfo:
        """Builds square-pixel intrinsics with the principal point near the image centre.

        Args:
            width: Image width, px.
            height: Image height, px.
            focal_px: fx = fy, px.
            centre_offset_px: Principal point minus the image centre ``((w-1)/2, (h-1)/2)``.
            distortion: Coefficients of ``distortion_model``.
            distortion_model: A key of :data:`DISTORTION_MODELS`.

        Returns:
            The camera info.

        Raises:
            LumpbeamError: A bad size, focal length or distortion.
        """
        cx = (width - 1) / 2.0 + centre_offset_px[0]
        cy = (height - 1) / 2.0 + centre_offset_px[1]
        k = np.array([[focal_px, 0.0, cx], [0.0, focal_px, cy], [0.0, 0.0, 1.0]])
        return CameraInfo(
            int(width), int(height), k, np.asarray(distortion, dtype=float), distortion_model
        )

    @cached_property
    def has_distortion(self) -> bool:
        """Whether the lens departs from a pinhole (an equidistant lens always does)."""
        return self.distortion_model == EQUIDISTANT or bool(np.any(self.d != 0.0))

    @cached_property
    def _pinhole(self) -> tuple[float, float, float, float, float]:
        """``(fx, fy, cx, cy, skew)`` as floats.

        The tracker applies K (or its inverse) to every frame's corners; the fields are fixed
        for the instance's life, so they are read out once.
        """
        k = self.k
        return float(k[0, 0]), float(k[1, 1]), float(k[0, 2]), float(k[1, 2]), float(k[0, 1])

    def check_image_size(self, width: int, height: int, source: str = 'image') -> None:
        """Checks that images of the given size belong to this calibration.

        Args:
            width: Image width, px.
            height: Image height, px.
            source: What the image is, for the message.

        Raises:
            LumpbeamError: The sizes differ (the calibration is for another sensor or
                binning, and would give wrong poses).
        """
        if (int(width), int(height)) != (self.width, self.height):
            raise LumpbeamError(
                f'camera info: calibrated for {self.width} x {self.height} px but the '
                f'{source} is {width} x {height} px'
            )

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
        return CameraInfo.pinhole(
            width,
            height,
            self.k[0, 0] * s,
            (offset[0] * s, offset[1] * s),
            tuple(self.d),
            self.distortion_model,
        )

    def distort_normalized(self, xy: np.ndarray) -> np.ndarray:
        """Applies the lens distortion to ideal normalized image coordinates.

        Args:
            xy: N x 2 coordinates ``(X / Z, Y / Z)`` of camera-frame points.

        Returns:
            N x 2 distorted normalized coordinates (apply K to get pixels).
        """
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        if not self.has_distortion:
            return xy
        x, y = xy[:, 0], xy[:, 1]
        r2 = x * x + y * y
        if self.distortion_model == EQUIDISTANT:
            k1, k2, k3, k4 = self._coefficients
            r = np.sqrt(r2)
            theta = np.arctan(r)
            t2 = theta * theta
            theta_d = theta * (1.0 + t2 * (k1 + t2 * (k2 + t2 * (k3 + t2 * k4))))
            # theta_d / r -> 1 on the optical axis.
            scale = np.divide(theta_d, r, out=np.ones_like(r), where=r > 1e-12)
            return np.asarray(xy * scale[:, None])
        k1, k2, p1, p2, k3 = self._coefficients[:5]
        radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3))
        if self.distortion_model == RATIONAL_POLYNOMIAL:
            k4, k5, k6 = self._coefficients[5:]
            radial = radial / (1.0 + r2 * (k4 + r2 * (k5 + r2 * k6)))
        xy_2 = 2.0 * x * y
        out = np.empty_like(xy)
        out[:, 0] = x * radial + p1 * xy_2 + p2 * (r2 + 2.0 * x * x)
        out[:, 1] = y * radial + p1 * (r2 + 2.0 * y * y) + p2 * xy_2
        return out

    @cached_property
    def _coefficients(self) -> tuple[float, ...]:
        """The distortion coefficients as floats (scalar arithmetic beats 0-d arrays')."""
        return tuple(float(v) for v in self.d)

    def undistort_normalized(self, xy_distorted: np.ndarray, iterations: int = 20) -> np.ndarray:
        """Inverts :meth:`distort_normalized`: OpenCV's estimate, polished by Newton's method.

        OpenCV's fixed-point iteration is fast but stops short for strong lenses; a Newton
        step or two on this model's own forward map makes the result exact.

        Args:
            xy_distorted: N x 2 distorted normalized coordinates.
            iterations: Newton steps at most (they stop once the model maps every point
                to within 1e-13 of its target).

        Returns:
            N x 2 ideal normalized coordinates (exact to round-off within the lens's field
            of view, where the distortion is one-to-one).
        """
        target = np.asarray(xy_distorted, dtype=float).reshape(-1, 2)
        # OpenCV returns None, not an empty array, for no points (a frame with no corner seen).
        if not self.has_distortion or target.size == 0:
            return target.copy()
        # OpenCV only here: reading a rig's configuration and projecting need none.
        import cv2

        # OpenCV's fixed-point iteration run to convergence (Newton only polishes the rest).
        criteria = (cv2.TERM_CRITERIA_COUNT | cv2.TERM_CRITERIA_EPS, 100, 1e-15)
        pts = np.ascontiguousarray(target).reshape(-1, 1, 2)
        if self.distortion_model == EQUIDISTANT:
            xy = cv2.fisheye.undistortPoints(pts, _EYE, self.d, criteria=criteria)
        elif hasattr(cv2, 'undistortPointsIter'):  # OpenCV 4: the variant with criteria
            xy = cv2.undistortPointsIter(pts, _EYE, self.d, None, None, criteria)
        else:  # OpenCV 5 folded it into undistortPoints
            xy = cv2.undistortPoints(pts, _EYE, self.d, None, None, None, criteria)
        xy = xy.reshape(-1, 2)
        if not np.all(np.isfinite(xy)):
            xy = target.copy()
        h = 1e-7
        for _ in range(iterations):
            f = self.distort_normalized(xy) - target
            if not np.max(np.abs(f), initial=0.0) > 1e-13:
                break  # 1e-13 of the focal length: well below a nanopixel
            # A 2x2 Jacobian per point by forward differences: the models are smooth.
            jx = (self.distort_normalized(xy + [h, 0.0]) - target - f) / h
            jy = (self.distort_normalized(xy + [0.0, h]) - target - f) / h
            det = jx[:, 0] * jy[:, 1] - jy[:, 0] * jx[:, 1]
            det = np.where(np.abs(det) < 1e-12, 1e-12, det)
            step = np.column_stack(
                [
                    (jy[:, 1] * f[:, 0] - jy[:, 0] * f[:, 1]) / det,
                    (jx[:, 0] * f[:, 1] - jx[:, 1] * f[:, 0]) / det,
                ]
            )
            xy -= step
        return xy

    def project(self, points: np.ndarray) -> np.ndarray:
        """Projects camera-frame points (N x 3, z forward) to real (distorted) pixels.

        Args:
            points: Points in the camera optical frame, m; z must be positive.

        Returns:
            N x 2 pixel coordinates.
        """
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        return self.to_pixels(self.distort_normalized(points[:, :2] / points[:, 2:3]))

    def to_pixels(self, xy: np.ndarray) -> np.ndarray:
        """Applies K to normalized coordinates (N x 2)."""
        fx, fy, cx, cy, skew = self._pinhole
        out = np.empty_like(xy, dtype=float)
        out[:, 0] = xy[:, 0] * fx + skew * xy[:, 1] + cx
        out[:, 1] = xy[:, 1] * fy + cy
        return out

    def to_normalized(self, pixels: np.ndarray) -> np.ndarray:
        """Applies K's inverse to pixels (N x 2)."""
        pixels = np.asarray(pixels, dtype=float).reshape(-1, 2)
        fx, fy, cx, cy, skew = self._pinhole
        out = np.empty_like(pixels)
        out[:, 1] = (pixels[:, 1] - cy) / fy
        out[:, 0] = (pixels[:, 0] - cx - skew * out[:, 1]) / fx
        return out

    def undistort_pixels(self, pixels: np.ndarray) -> np.ndarray:
        """Maps measured (distorted) pixels to where an ideal pinhole camera sees them.

        Args:
            pixels: N x 2 pixel coordinates.

        Returns:
            N x 2 ideal pinhole pixel coordinates with the same K (the identity without
            distortion).
        """
        if not self.has_distortion:
            return np.asarray(pixels, dtype=float).reshape(-1, 2)
        return self.to_pixels(self.undistort_normalized(self.to_normalized(pixels)))

    def pinhole_only(self) -> CameraInfo:
        """Returns the same K without distortion (the camera the pose fit works in)."""
        return replace(self, d=np.zeros(5), distortion_model=PLUMB_BOB)
