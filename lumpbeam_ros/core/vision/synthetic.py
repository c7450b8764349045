"""The synthetic camera: what a camera on the beam tip sees of the checkerboard.

Each frame integrates the tip's motion over the exposure (motion blur), renders the board by
warping a supersampled texture and averaging it down (anti-aliasing), applies the lens
distortion, a Gaussian defocus blur and additive sensor noise, and quantizes to mono8.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import cv2
import numpy as np
from scipy.interpolate import CubicSpline

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.vision.camera_model import CameraInfo
from lumpbeam_ros.core.vision.config import CameraConfig
from lumpbeam_ros.core.vision.pose import PlaneModel, camera_board_transform


@dataclass(frozen=True)
class SyntheticFrame:
    """One rendered frame.

    Attributes:
        index: Frame number in the sequence.
        stamp: Middle of the exposure, s.
        image: The mono8 image (height x width, uint8).
        truth: The tip pose ``(x, z, pitch)`` at ``stamp``.
        motion_samples: Sub-poses integrated over the exposure.
    """

    index: int
    stamp: float
    image: np.ndarray
    truth: np.ndarray
    motion_samples: int


class SyntheticCamera:
    """Renders the checkerboard as seen from the tip, deterministically for a given seed.

    Args:
        config: Camera, rig and rendering settings.
        seed: Noise seed; ``None`` takes ``config.synthetic.seed``.
    """

    def __init__(self, config: CameraConfig, seed: int | None = None):
        self.config = config
        self.camera_info: CameraInfo = config.camera_info
        self._settings = config.synthetic
        self._seed = config.synthetic.seed if seed is None else int(seed)
        self._model = PlaneModel(config.rig, config.camera_info)
        rig = config.rig
        # Texels per square so one texel is about one rendered (supersampled) pixel at the
        # board's distance: bilinear sampling then integrates each pixel over its footprint.
        board_centre = rig.base_board.translation
        centre_pose = np.array([board_centre[0], board_centre[2], 0.0])
        depth = camera_board_transform(rig, centre_pose).translation[2]
        if depth <= 0:
            raise LumpbeamError('synthetic camera: the board is behind the camera')
        s = self._settings.supersample
        per_square = s * self.camera_info.k[0, 0] * rig.board.square_size_m / depth
        self._texture, tex_to_board = rig.board.texture(
            max(4, int(round(per_square))), self._settings.dark_dn, self._settings.light_dn
        )
        self._tex_to_board = tex_to_board
        self._distortion_maps: tuple[np.ndarray, np.ndarray] | None = None
        self._buffers: tuple[np.ndarray, np.ndarray] | None = None

    def _homography(self, pose: np.ndarray) -> np.ndarray:
        """Maps texture texels to ideal image pixels for one tip pose."""
        camera_board = camera_board_transform(self.config.rig, pose)
        r, t = camera_board.rotation, camera_board.translation
        plane = np.column_stack([r[:, 0], r[:, 1], t])
        return np.asarray(self.camera_info.k @ plane @ self._tex_to_board)

    def _outline_px(self, poses: np.ndarray) -> np.ndarray:
        """Returns the image positions of the sheet's corners for every pose (4M x 2)."""
        outline = self.config.rig.board.outline_m
        pts = []
        for pose in poses:
            cam = camera_board_transform(self.config.rig, pose).apply(outline)
            if np.any(cam[:, 2] <= 0):
                raise LumpbeamError('synthetic camera: the board is behind the camera')
            pts.append(cam[:, :2] / cam[:, 2:3] * np.diag(self.camera_info.k)[:2])
        return np.asarray(np.concatenate(pts) + self.camera_info.k[:2, 2])

    def motion_samples(self, start: np.ndarray, end: np.ndarray) -> int:
        """Sub-poses needed so no corner moves more than ``motion_step_px`` between two.

        Args:
            start: Tip pose at the start of the exposure.
            end: Tip pose at its end.

        Returns:
            The number of sub-poses, between 1 and ``max_motion_samples``.
        """
        shift = np.max(
            np.linalg.norm(self._model.project(end) - self._model.project(start), axis=1)
        )
        n = int(np.ceil(shift / self._settings.motion_step_px))
        return int(np.clip(n, 1, self._settings.max_motion_samples))

    def render(self, poses: np.ndarray, noise_key: int = 0) -> np.ndarray:
        """Renders one frame that integrates the given sub-poses equally.

        Args:
            poses: Tip poses ``(x, z, pitch)`` over the exposure (M x 3, or one pose).
            noise_key: Selects the noise realization (with the seed): the same key gives the
                same image.

        Returns:
            The mono8 image (height x width, uint8).

        Raises:
            LumpbeamError: The board would be behind the camera.
        """
        poses = np.atleast_2d(np.asarray(poses, dtype=float))
        st = self._settings
        w, h = self.camera_info.width, self.camera_info.height
        image: np.ndarray = np.full((h, w), st.wall_dn, dtype=np.float32)
        outline = self._outline_px(poses)
        pad = 3 + int(np.ceil(4 * st.defocus_sigma_px))
        x0 = max(int(np.floor(outline[:, 0].min())) - pad, 0)
        y0 = max(int(np.floor(outline[:, 1].min())) - pad, 0)
        x1 = min(int(np.ceil(outline[:, 0].max())) + pad + 1, w)
        y1 = min(int(np.ceil(outline[:, 1].max())) + pad + 1, h)
        if x1 > x0 and y1 > y0:
            image[y0:y1, x0:x1] = self._render_roi(poses, x0, y0, x1 - x0, y1 - y0)
        if self.camera_info.has_distortion:
            map_x, map_y = self._distortion_map()
            image = cv2.remap(
                image, map_x, map_y, cv2.INTER_LINEAR, borderMode=cv2.BORDER_CONSTANT,
                borderValue=st.wall_dn,
            )  # fmt: skip
            x0, y0, x1, y1 = 0, 0, w, h
        if st.defocus_sigma_px > 0 and x1 > x0 and y1 > y0:
            # The wall is uniform, so blurring the board's region alone is exact.
            roi = np.ascontiguousarray(image[y0:y1, x0:x1])
            image[y0:y1, x0:x1] = cv2.GaussianBlur(
                roi, (0, 0), st.defocus_sigma_px, borderType=cv2.BORDER_REPLICATE
            )
        if st.noise_sigma_dn > 0:
            rng = np.random.default_rng([self._seed, int(noise_key)])
            image += rng.standard_normal(image.shape, dtype=np.float32) * np.float32(
                st.noise_sigma_dn
            )
        return np.asarray(np.clip(np.rint(image), 0, 255), dtype=np.uint8)

    def _render_roi(
        self, poses: np.ndarray, x0: int, y0: int, width: int, height: int
    ) -> np.ndarray:
        s = self._settings.supersample
        # Ideal pixel (u, v) -> supersampled pixel s (u - x0 + 0.5) - 0.5 of the region, so
        # that averaging s x s blocks puts each block's mean at the ideal pixel's centre.
        to_fine = np.array(
            [[s, 0.0, s * (0.5 - x0) - 0.5], [0.0, s, s * (0.5 - y0) - 0.5], [0.0, 0.0, 1.0]]
        )
        # Reused buffers: fresh 30 MB arrays per sub-pose cost more in page faults than
        # the warp itself.
        if self._buffers is None:
            shape = (self.camera_info.height * s, self.camera_info.width * s)
            self._buffers = (np.empty(shape, np.float32), np.empty(shape, np.float32))
        acc = self._buffers[0][: height * s, : width * s]
        layer = self._buffers[1][: height * s, : width * s]
        for i, pose in enumerate(poses):
            cv2.warpPerspective(
                self._texture, to_fine @ self._homography(pose), (width * s, height * s),
                dst=acc if i == 0 else layer, flags=cv2.INTER_LINEAR,
                borderMode=cv2.BORDER_CONSTANT, borderValue=self._settings.wall_dn,
            )  # fmt: skip
            if i > 0:
                cv2.add(acc, layer, dst=acc)
        if s > 1:
            acc = cv2.resize(acc, (width, height), interpolation=cv2.INTER_AREA)
        return acc * np.float32(1.0 / len(poses))

    def _distortion_map(self) -> tuple[np.ndarray, np.ndarray]:
        """For every real (distorted) pixel, where the ideal pinhole image has it."""
        if self._distortion_maps is None:
            w, h = self.camera_info.width, self.camera_info.height
            grid = np.mgrid[0:h, 0:w].astype(np.float64)
            pixels = np.column_stack([grid[1].ravel(), grid[0].ravel()])
            ideal = self.camera_info.undistort_pixels(pixels).astype(np.float32)
            self._distortion_maps = (
                ideal[:, 0].reshape(h, w).copy(),
                ideal[:, 1].reshape(h, w).copy(),
            )
        return self._distortion_maps

    def render_trajectory(
        self,
        t: np.ndarray,
        x: np.ndarray,
        z: np.ndarray,
        pitch: np.ndarray,
        frame_times: np.ndarray | None = None,
    ) -> Iterator[SyntheticFrame]:
        """Renders a frame per exposure along a sampled tip trajectory.

        The trajectory is interpolated by cubic splines, so sub-poses within an exposure
        follow the motion's curvature (linear interpolation between 180 Hz samples would
        bias the blurred image by several micrometres).

        Args:
            t: Sample times, s, strictly increasing (at least 4 samples).
            x: Tip x, m.
            z: Tip z, m.
            pitch: Tip pitch, rad.
            frame_times: Middle of each exposure, s; ``None`` renders one frame per sample.

        Yields:
            Frames in order.

        Raises:
            LumpbeamError: The arrays have different lengths, are too short, are not finite
                or ``t`` is not increasing.
        """
        arrays = [np.asarray(a, dtype=float).ravel() for a in (t, x, z, pitch)]
        if len({a.size for a in arrays}) != 1 or arrays[0].size < 4:
            raise LumpbeamError('trajectory: t, x, z, pitch need equal lengths of at least 4')
        if not all(np.all(np.isfinite(a)) for a in arrays) or np.any(np.diff(arrays[0]) <= 0):
            raise LumpbeamError('trajectory: values must be finite and t strictly increasing')
        spline = CubicSpline(arrays[0], np.column_stack(arrays[1:]), axis=0)
        times = arrays[0] if frame_times is None else np.asarray(frame_times, dtype=float)
        exposure = self._settings.exposure_s
        for index, stamp in enumerate(times):
            n = 1
            if exposure > 0:
                ends = spline([stamp - exposure / 2, stamp + exposure / 2])
                n = self.motion_samples(ends[0], ends[1])
            offsets = ((np.arange(n) + 0.5) / n - 0.5) * exposure
            poses = spline(stamp + offsets)
            yield SyntheticFrame(
                index, float(stamp), self.render(poses, index), spline(stamp).copy(), n
            )
