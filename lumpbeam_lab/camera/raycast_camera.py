"""An independent camera renderer: per-pixel ray casting onto the checkerboard.

It is the second opinion on the tracker, so it shares nothing with the tracker's camera model,
geometry or board code (nor with :mod:`lumpbeam_ros.core.vision.synthetic`, which warps a texture):

* each sub-pixel sample's ray is found once, by inverting the lens model here (Newton's
  method on this module's own forward model of plumb_bob, rational_polynomial and
  equidistant lenses);
* per frame the rays are intersected with the board plane, in closed form, at several tip
  poses across the exposure (motion blur), and the printed pattern is evaluated analytically
  at the hit points, box-filtered over each sample's footprint (anti-aliasing on top of the
  supersampling);
* pixels far from any edge of the pattern at every pose of the exposure take their
  square's value directly; only the pixels near an edge are supersampled;
* then a Gaussian defocus, an illumination gradient times a frame-to-frame flicker, Gaussian
  noise and quantization to mono8.

Frames (all lengths in metres, angles in radians): ``beam_base`` (x along the beam, z up),
the tip frame at ``(x, 0, z)`` turned by ``pitch`` about +y, the camera's optical frame
(z forward, x right, y down) fixed on the tip, and the board frame (origin at the centre of
the squares, x along a row, y down the board, z into the wall) fixed in ``beam_base``.
Pixel centres are at integer coordinates (ROS and OpenCV's convention).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError

_MODELS = {'plumb_bob': 5, 'rational_polynomial': 8, 'equidistant': 4}


@dataclass(frozen=True)
class Lens:
    """The camera's intrinsics as ROS ``camera_info`` gives them.

    Attributes:
        width: Image width, px.
        height: Image height, px.
        fx: Focal length along x, px.
        fy: Focal length along y, px.
        cx: Principal point x, px.
        cy: Principal point y, px.
        model: ``'plumb_bob'``, ``'rational_polynomial'`` or ``'equidistant'``.
        coefficients: The model's distortion coefficients, in ROS order.
    """

    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float
    model: str = 'plumb_bob'
    coefficients: tuple[float, ...] = (0.0, 0.0, 0.0, 0.0, 0.0)

    def __post_init__(self) -> None:
        if _MODELS.get(self.model) != len(self.coefficients):
            raise LumpbeamError(
                f'raycast lens: {self.model!r} with {len(self.coefficients)} coefficients'
            )


@dataclass(frozen=True)
class Scene:
    """The printed board, where it hangs and where the camera sits on the tip.

    Attributes:
        squares_x: Squares along the board's x axis.
        squares_y: Squares along its y axis.
        square_m: Edge of a square, m.
        margin_squares: White border around the squares, in squares.
        mount_xyz: Camera origin in the tip frame, m.
        mount_rpy: Camera orientation in the tip frame, roll-pitch-yaw (URDF), rad.
        board_xyz: Board origin in ``beam_base``, m.
        board_rpy: Board orientation in ``beam_base``, roll-pitch-yaw (URDF), rad.
    """

    squares_x: int
    squares_y: int
    square_m: float
    margin_squares: float
    mount_xyz: tuple[float, float, float]
    mount_rpy: tuple[float, float, float]
    board_xyz: tuple[float, float, float]
    board_rpy: tuple[float, float, float]


@dataclass(frozen=True)
class Optics:
    """Image formation beyond the geometry.

    Attributes:
        supersample: Samples per pixel along each axis near the pattern's edges.
        defocus_px: Standard deviation of the Gaussian defocus, px.
        gradient: Peak-to-peak illumination change across the image (0.3: +-15 %).
        gradient_angle_rad: Direction of the illumination gradient in the image.
        flicker: Frame-to-frame illumination change, uniform within +-``flicker``.
        noise_dn: Standard deviation of the sensor noise, DN.
        dark_dn: Grey level of the dark squares under unit illumination.
        light_dn: Grey level of the light squares and the margin.
        wall_dn: Grey level of the wall.
        seed: Seed of the noise and the flicker.
    """

    supersample: int = 2
    defocus_px: float = 0.0
    gradient: float = 0.0
    gradient_angle_rad: float = 0.5
    flicker: float = 0.0
    noise_dn: float = 0.0
    dark_dn: float = 35.0
    light_dn: float = 215.0
    wall_dn: float = 100.0
    seed: int = 0


def _axis_rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues' formula: the rotation by ``angle`` about the unit vector ``axis``."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.asarray(np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * (k @ k))


def _homogeneous(xyz: tuple[float, float, float], rpy: tuple[float, float, float]) -> np.ndarray:
    """4x4 pose of a child frame: yaw about z of the parent, then pitch, then roll."""
    m = np.eye(4)
    rotation = np.eye(3)
    for axis, angle in zip(np.eye(3)[::-1], rpy[::-1], strict=True):
        rotation = rotation @ _axis_rotation(axis, angle)
    m[:3, :3] = rotation
    m[:3, 3] = xyz
    return m


def _rigid_inverse(m: np.ndarray) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3] = m[:3, :3].T
    out[:3, 3] = -m[:3, :3].T @ m[:3, 3]
    return out


def lens_distort(lens: Lens, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The lens model: ideal normalized coordinates to distorted normalized coordinates.

    Args:
        lens: The lens.
        x: Ideal ``X / Z``.
        y: Ideal ``Y / Z``.

    Returns:
        Distorted ``(x, y)``.
    """
    c = lens.coefficients
    r2 = x * x + y * y
    if lens.model == 'equidistant':
        r = np.sqrt(r2)
        theta = np.arctan(r)
        th2 = theta * theta
        poly = 1.0 + c[0] * th2 + c[1] * th2**2 + c[2] * th2**3 + c[3] * th2**4
        ratio = np.where(r > 1e-15, theta * poly / np.maximum(r, 1e-15), 1.0)
        return x * ratio, y * ratio
    gain = 1.0 + c[0] * r2 + c[1] * r2**2 + c[4] * r2**3
    if lens.model == 'rational_polynomial':
        gain = gain / (1.0 + c[5] * r2 + c[6] * r2**2 + c[7] * r2**3)
    xd = x * gain + 2.0 * c[2] * x * y + c[3] * (r2 + 2.0 * x * x)
    yd = y * gain + c[2] * (r2 + 2.0 * y * y) + 2.0 * c[3] * x * y
    return xd, yd


def lens_rays(lens: Lens, u: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Inverts the lens: pixels to ideal normalized coordinates (the rays ``(x, y, 1)``).

    Newton's method with a central-difference Jacobian, from the distorted point; it stops
    when no point moves more than 1e-13.

    Args:
        lens: The lens.
        u: Pixel x (any shape).
        v: Pixel y.

    Returns:
        ``(x, y)`` with ``lens_distort(x, y)`` equal to the normalized pixel.

    Raises:
        LumpbeamError: The inversion does not converge (a lens folding over itself).
    """
    u, v = np.broadcast_arrays(np.asarray(u, dtype=np.float64), np.asarray(v, dtype=np.float64))
    yd = (v - lens.cy) / lens.fy
    xd = (u - lens.cx) / lens.fx
    x, y = xd.copy(), yd.copy()
    for _ in range(50):
        fx, fy = lens_distort(lens, x, y)
        ex, ey = fx - xd, fy - yd
        i11, i12, i21, i22 = _inverse_jacobian(lens, x, y)
        dx = i11 * ex + i12 * ey
        dy = i21 * ex + i22 * ey
        x -= dx
        y -= dy
        if np.max(np.abs(dx)) < 1e-13 and np.max(np.abs(dy)) < 1e-13:
            return x, y
    raise LumpbeamError('raycast lens: the distortion could not be inverted over the image')


def _inverse_jacobian(lens: Lens, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, ...]:
    """d(ideal)/d(distorted) at ideal ``(x, y)``: the inverse of the lens's 2x2 Jacobian."""
    h = 1e-6
    ax1, ay1 = lens_distort(lens, x + h, y)
    ax0, ay0 = lens_distort(lens, x - h, y)
    bx1, by1 = lens_distort(lens, x, y + h)
    bx0, by0 = lens_distort(lens, x, y - h)
    j11, j21 = (ax1 - ax0) / (2 * h), (ay1 - ay0) / (2 * h)
    j12, j22 = (bx1 - bx0) / (2 * h), (by1 - by0) / (2 * h)
    det = j11 * j22 - j12 * j21
    return j22 / det, -j12 / det, -j21 / det, j11 / det


class RaycastCamera:
    """Renders mono8 frames of the board seen from the tip by ray casting.

    Args:
        lens: The intrinsics.
        scene: Board and mount.
        optics: Blur, illumination, noise.
    """

    def __init__(self, lens: Lens, scene: Scene, optics: Optics):
        self.lens = lens
        self.scene = scene
        self.optics = optics
        self._tip_camera = _homogeneous(scene.mount_xyz, scene.mount_rpy)
        self._base_board = _homogeneous(scene.board_xyz, scene.board_rpy)
        h, w = lens.height, lens.width
        s = optics.supersample
        offsets = (np.arange(s) + 0.5) / s - 0.5
        shifts = [(du, dv) for dv in offsets for du in offsets]
        self._centre_rays = (np.empty((h, w), np.float32), np.empty((h, w), np.float32))
        self._sub_rays = np.empty((2, len(shifts), h, w), np.float32)
        u = np.arange(w, dtype=np.float64)[None, :]
        # A band of rows at a time bounds the memory. The sub-samples' rays follow from
        # the centre's by the inverse lens Jacobian: the second-order term is below 1e-4 px
        # at a quarter pixel for any lens in the validation range.
        for top in range(0, h, 128):
            v = np.arange(top, min(top + 128, h), dtype=np.float64)[:, None]
            x, y = lens_rays(lens, u, v)
            rows = slice(top, top + v.shape[0])
            self._centre_rays[0][rows], self._centre_rays[1][rows] = x, y
            inverse = _inverse_jacobian(lens, x, y)
            for i, (du, dv) in enumerate(shifts):
                ddx, ddy = du / lens.fx, dv / lens.fy
                self._sub_rays[0, i, rows] = x + inverse[0] * ddx + inverse[1] * ddy
                self._sub_rays[1, i, rows] = y + inverse[2] * ddx + inverse[3] * ddy
        # Size of one sub-sample on the board, in squares, at the centre of the view:
        # the width of the box filter that anti-aliases each sample.
        depth = abs(self._board_in_camera(np.zeros(3))[2, 3])
        self._footprint = np.float32(depth / (lens.fx * s) / scene.square_m)
        self._px_per_square = lens.fx * scene.square_m / depth
        gy, gx = np.mgrid[0:h, 0:w].astype(np.float32)
        ramp = (gx - w / 2) * np.cos(optics.gradient_angle_rad) + (gy - h / 2) * np.sin(
            optics.gradient_angle_rad
        )
        span = float(np.max(ramp) - np.min(ramp))
        self._illumination = (1.0 + optics.gradient * ramp / span).astype(np.float32)

    def _board_in_camera(self, tip_pose: np.ndarray) -> np.ndarray:
        x, z, pitch = (float(v) for v in tip_pose)
        base_tip = np.eye(4)
        base_tip[:3, :3] = _axis_rotation(np.array([0.0, 1.0, 0.0]), pitch)
        base_tip[:3, 3] = [x, 0.0, z]
        return np.asarray(_rigid_inverse(base_tip @ self._tip_camera) @ self._base_board)

    def _ray_to_squares(self, tip_pose: np.ndarray) -> np.ndarray:
        """3x3 map from a ray ``(x, y, 1)`` to homogeneous square coordinates.

        Square coordinates ``(a, b)`` count squares from the top-left corner of the squares
        (the dark corner square is ``0 <= a, b < 1``).
        """
        m = self._board_in_camera(tip_pose)
        if m[2, 3] <= 0:
            raise LumpbeamError('raycast camera: the board is behind the camera')
        # A board point (bx, by, 0) is seen along [r1 r2 t] (bx, by, 1).
        plane = np.column_stack([m[:3, 0], m[:3, 1], m[:3, 3]])
        sc = self.scene
        to_squares = np.array(
            [
                [1.0 / sc.square_m, 0.0, sc.squares_x / 2.0],
                [0.0, 1.0 / sc.square_m, sc.squares_y / 2.0],
                [0.0, 0.0, 1.0],
            ]
        )
        return to_squares @ np.linalg.inv(plane)

    @staticmethod
    def _map(g: np.ndarray, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        g = g.astype(np.float32)
        w = g[2, 0] * x
        w += g[2, 1] * y
        w += g[2, 2]
        if not np.min(w) > 0:
            raise LumpbeamError('raycast camera: a ray misses the board plane')
        np.divide(np.float32(1.0), w, out=w)
        a = g[0, 0] * x
        a += g[0, 1] * y
        a += g[0, 2]
        a *= w
        b = g[1, 0] * x
        b += g[1, 1] * y
        b += g[1, 2]
        b *= w
        return a, b

    def _filtered(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """The printed pattern at square coordinates, box-filtered over one footprint.

        Along each axis the pattern is a +-1 square wave; a box of width ``w`` turns each
        step into a linear ramp, and the box filter of the checker (the product of the
        two waves) is the product of the filtered waves. The outer edges of the squares
        and of the sheet are ramps of the same width.
        """
        sc, op = self.scene, self.optics
        inv_w = np.float32(1.0 / self._footprint)

        def ramp(d: np.ndarray) -> np.ndarray:  # a step at d = 0 through the box: 0 ... 1
            out = d * inv_w
            out += np.float32(0.5)
            np.clip(out, 0.0, 1.0, out=out)
            return out

        def wave(c: np.ndarray) -> np.ndarray:  # +1 on cells with an even index
            n = np.rint(c)
            up = ramp(c - n)
            up *= np.float32(2.0)
            up -= np.float32(1.0)
            odd = (n.astype(np.int32) & 1).astype(bool)
            np.negative(up, out=up, where=odd)
            return up

        m = np.float32(sc.margin_squares)
        edge_a = np.minimum(a, np.float32(sc.squares_x) - a)
        edge_b = np.minimum(b, np.float32(sc.squares_y) - b)
        in_squares = ramp(np.minimum(edge_a, edge_b))
        in_sheet = ramp(np.minimum(edge_a, edge_b) + m)
        checker = wave(a)
        checker *= wave(b)
        mid, half = (op.light_dn + op.dark_dn) / 2.0, (op.light_dn - op.dark_dn) / 2.0
        squares = np.float32(mid - op.light_dn) - np.float32(half) * checker
        squares *= in_squares
        in_sheet *= np.float32(op.light_dn - op.wall_dn)
        squares += in_sheet
        squares += np.float32(op.wall_dn)
        return squares

    def _cell_value(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """The printed pattern at square coordinates, unfiltered (a point sample)."""
        sc, op = self.scene, self.optics
        m = sc.margin_squares
        ia, ib = np.floor(a).astype(np.int32), np.floor(b).astype(np.int32)
        in_squares = (ia >= 0) & (ia < sc.squares_x) & (ib >= 0) & (ib < sc.squares_y)
        in_sheet = (a >= -m) & (a < sc.squares_x + m) & (b >= -m) & (b < sc.squares_y + m)
        value = np.full(a.shape, op.wall_dn, np.float32)
        value[in_sheet] = op.light_dn
        value[in_squares & (((ia + ib) & 1) == 0)] = op.dark_dn
        return value

    def _edge_distance(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Distance to the nearest edge of the pattern, in squares."""
        sc, m = self.scene, self.scene.margin_squares
        d: np.ndarray = np.minimum(np.abs(a - np.rint(a)), np.abs(b - np.rint(b)))
        if m != round(m):
            # The sheet's edges are off the grid of square edges.
            for edge_a in (-m, sc.squares_x + m):
                np.minimum(d, np.abs(a - np.float32(edge_a)), out=d)
            for edge_b in (-m, sc.squares_y + m):
                np.minimum(d, np.abs(b - np.float32(edge_b)), out=d)
        return d

    def _motion_squares(self, maps: list[np.ndarray]) -> float:
        """How far, in squares, any point of the view moves on the board over the exposure."""
        x, y = (
            r[:: max(1, r.shape[0] // 8), :: max(1, r.shape[1] // 8)] for r in self._centre_rays
        )
        spots = [np.stack(self._map(g, x, y)) for g in maps]
        return max(float(np.max(np.abs(p - spots[0]))) for p in spots)

    def render(self, tip_poses: np.ndarray, frame_index: int = 0) -> np.ndarray:
        """Renders one frame integrating the scene equally over the given tip poses.

        Args:
            tip_poses: Tip ``(x, z, pitch)`` at the sub-exposure instants (M x 3).
            frame_index: Selects the noise and flicker (with the seed).

        Returns:
            The mono8 image (height x width).

        Raises:
            LumpbeamError: The board is behind the camera or off its plane's side.
        """
        poses = np.atleast_2d(np.asarray(tip_poses, dtype=float))
        maps = [self._ray_to_squares(p) for p in poses]
        a, b = self._map(maps[len(maps) // 2], *self._centre_rays)
        image = self._cell_value(a, b)
        # Pixels within 1.5 px of an edge (plus the motion over the exposure) are
        # supersampled; elsewhere the pixel's whole footprint sees one colour throughout.
        band = 1.5 * 1.5 / self._px_per_square + self._motion_squares(maps)
        rows, cols = np.nonzero(self._edge_distance(a, b) < np.float32(band))
        xs = self._sub_rays[0][:, rows, cols]
        ys = self._sub_rays[1][:, rows, cols]
        total = np.zeros(xs.shape, np.float32)
        for g in maps:
            total += self._filtered(*self._map(g, xs, ys))
        image[rows, cols] = total.mean(axis=0) / np.float32(len(maps))
        return self._expose(image, frame_index)

    def _expose(self, radiance: np.ndarray, frame_index: int) -> np.ndarray:
        op = self.optics
        rng = np.random.default_rng([op.seed, int(frame_index)])
        gain = np.float32(1.0 + rng.uniform(-op.flicker, op.flicker))
        image = radiance
        image *= self._illumination
        image *= gain
        if op.defocus_px > 0:
            image = cv2.GaussianBlur(image, (0, 0), op.defocus_px, borderType=cv2.BORDER_REPLICATE)
        if op.noise_dn > 0:
            noise = rng.standard_normal(image.shape, dtype=np.float32)
            noise *= np.float32(op.noise_dn)
            image += noise
        np.rint(image, out=image)
        return np.clip(image, 0, 255, out=image).astype(np.uint8)
