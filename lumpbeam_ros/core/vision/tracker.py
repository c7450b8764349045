"""The tip tracker: camera frames in, tip poses in ``beam_base`` out.

Per frame: predict the corners from the last two frames (constant velocity in pixels),
refine them in small windows, verify each one (:mod:`lumpbeam_ros.core.vision.partial`: those out
of view or occluded are dropped, so a partial view still gives a pose above a minimum), and
fit the tip's ``(x, z, pitch)`` to them with the plane-constrained model, or the full 6-DoF
pose with the free model (:mod:`lumpbeam_ros.core.vision.free_pose`). When tracking fails, or
there is nothing to track, the full detector searches the frame (it needs the whole board).
The first good frames also feed a one-off calibration of the rig's fixed unknowns.

A node only converts messages and calls :meth:`TipTracker.process`; every problem with a
frame comes back as a status, never as an exception or a stale pose.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from enum import Enum
from typing import Any

import cv2
import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.vision.calibration import RigCalibration, calibrate_rig
from lumpbeam_ros.core.vision.camera_model import CameraInfo
from lumpbeam_ros.core.vision.config import CameraConfig, RigGeometry
from lumpbeam_ros.core.vision.corners import (
    corner_contrast,
    grid_is_regular,
    homography_residual,
    refine_corners,
)
from lumpbeam_ros.core.vision.detect import detect_board
from lumpbeam_ros.core.vision.free_pose import (
    POSE_MODELS,
    FreeModel,
    free_pose_from_board_pose,
    planar_part,
)
from lumpbeam_ros.core.vision.partial import (
    OUTLIER_FLOOR_PX,
    OUTLIER_MEDIANS,
    board_polarity,
    colours_as_expected,
    coverage_problem,
    labelling_is_unambiguous,
    reject_outliers,
    select_corners,
)
from lumpbeam_ros.core.vision.pose import (
    PlaneModel,
    camera_board_transform,
    solve_board_pnp,
    tip_pose_from_board_pose,
)
from lumpbeam_ros.core.vision.reprojection import PoseFit, sorted_median

#: Image encodings :meth:`TipTracker.process` takes (those of doc/interfaces.md, 'Topics').
ENCODINGS = ('mono8', 'bgr8', 'rgb8')


class TrackStatus(str, Enum):
    """Why a frame did or did not give a pose."""

    OK = 'ok'
    BAD_IMAGE = 'bad_image'
    TOO_DARK = 'too_dark'
    SATURATED = 'saturated'
    BOARD_NOT_FOUND = 'board_not_found'
    CORNERS_REJECTED = 'corners_rejected'
    POSE_REJECTED = 'pose_rejected'
    TOO_FEW_CORNERS = 'too_few_corners'
    NO_CAMERA_INFO = 'no_camera_info'
    RIG_MISMATCH = 'rig_mismatch'


@dataclass(frozen=True)
class TrackResult:
    """The outcome of one frame.

    Attributes:
        stamp: The frame's stamp, s.
        status: :class:`TrackStatus`.
        reason: One human-readable line (empty when OK).
        pose: Tip ``(x, z, pitch)`` in ``beam_base`` (m, m, rad), or ``None``.
        covariance: 3x3 covariance of ``pose`` from the reprojection residuals, or ``None``.
        rms_px: RMS reprojection error per corner, px (NaN without a fit).
        corners: The measured (distorted) corner pixels (N x 2), or ``None``.
        detected: Whether the full detector ran on this frame (tracking was lost or new).
        calibrated: Whether the rig's fixed unknowns were already estimated (always in
            the free model: it fits them in every frame).
        corners_used: Corners the fit used (fewer than the board's in a partial view).
        pose6: Free model only: ``(x, y, z, roll, pitch, yaw)`` of the tip in
            ``beam_base`` (``pose`` is then its in-plane part); ``None`` in the plane model.
        covariance6: Free model only: 6x6 covariance of ``pose6`` (PoseWithCovariance
            order), or ``None``.
    """

    stamp: float
    status: TrackStatus
    reason: str = ''
    pose: np.ndarray | None = None
    covariance: np.ndarray | None = None
    rms_px: float = math.nan
    corners: np.ndarray | None = None
    detected: bool = False
    calibrated: bool = False
    corners_used: int = 0
    pose6: np.ndarray | None = None
    covariance6: np.ndarray | None = None

    @property
    def ok(self) -> bool:
        """Whether the frame gave a pose."""
        return self.status is TrackStatus.OK


def _failure(stamp: float, status: TrackStatus, reason: str, **extra: Any) -> TrackResult:
    return TrackResult(stamp, status, reason, **extra)


class TipTracker:
    """Tracks the tip pose through a stream of frames.

    Args:
        camera_info: The camera's intrinsics (from ``/camera/camera_info`` or the config).
        config: Rig geometry and tracker settings (``config/camera.yaml``); its own
            ``camera_info`` is not used.
        pose_model: ``'plane'`` (the tip moves in the plane of bending: ``x, z, pitch``) or
            ``'free'`` (the full 6-DoF pose; no rig calibration).

    Raises:
        LumpbeamError: The configuration is unusable: the board is behind the camera or not
            in view at the rig's reference pose (plane model), or an unknown pose model.
    """

    def __init__(self, camera_info: CameraInfo, config: CameraConfig, pose_model: str = 'plane'):
        if pose_model not in POSE_MODELS:
            raise LumpbeamError(
                f'tracker: pose model {pose_model!r} is not one of {", ".join(POSE_MODELS)}'
            )
        self.pose_model = pose_model
        self.camera_info = camera_info
        self.config = config
        self.settings = config.tracker
        self._board = config.rig.board
        self._object_xy = self._board.object_points()[:, :2]
        self._calibration: RigCalibration | None = None
        self._set_rig(config.rig)
        self._configured_distance_m = self._board_distance_m
        # Why every frame is refused, once the board seen is found not to be the one
        # configured: its poses would be scaled by the ratio of the squares (a wrong value).
        self._mismatch = ''
        self._pending: list[tuple[np.ndarray, np.ndarray]] = []
        self._whole_board_coverage: str | None = None
        self.reset()

    def _set_rig(self, rig: RigGeometry) -> None:
        self._model = PlaneModel(rig, self.camera_info)
        self._free = FreeModel(rig, self.camera_info)
        centre = rig.base_board.translation
        reference = np.array([centre[0], centre[2], 0.0])
        camera_board = camera_board_transform(rig, reference)
        self._board_distance_m = float(camera_board.translation[2])
        # The free model needs no reference pose: with identity extrinsics (the camera's
        # pose in the board's frame) the detector's corners set the window instead.
        self._window_from_detection = camera_board.translation[2] <= 0
        if self._window_from_detection and self.pose_model == 'plane':
            raise LumpbeamError('tracker: the configured board is behind the camera')
        self._expected_rotation = camera_board.rotation
        # Image directions of the board's axes (a fronto-parallel approximation suffices:
        # they only decide between labellings 180 degrees apart).
        self._expected_axes = camera_board.rotation[:2, :2].T.copy()
        self._half_window = 5
        if not self._window_from_detection:
            self._half_window = self._window_for(self._model.project(reference))

    def _window_for(self, corners: np.ndarray) -> int:
        spacing = np.median(np.linalg.norm(np.diff(corners, axis=0), axis=1))
        largest = self.settings.max_window_px
        return int(np.clip(round(self.settings.window_fraction * spacing), 3, largest))

    @property
    def calibration(self) -> RigCalibration | None:
        """The estimate of the rig's fixed unknowns, once made."""
        return self._calibration

    @property
    def half_window(self) -> int:
        """Corner refinement window half-size, px."""
        return self._half_window

    def reset(self) -> None:
        """Forgets the tracking history (the next frame runs full detection)."""
        self._history: list[tuple[float, np.ndarray, np.ndarray]] = []
        # How far the last tracked frame's corners were from their prediction, px (infinite
        # after a detection): a partial view is trusted only after a close prediction.
        self._prediction_error = math.inf
        self._polarity: float | None = None

    def process(self, image: np.ndarray, stamp: float, encoding: str = 'mono8') -> TrackResult:
        """Measures the tip pose in one frame.

        Args:
            image: H x W (mono8) or H x W x 3 (bgr8, rgb8) uint8 array.
            stamp: Middle of the exposure, s.
            encoding: ``'mono8'``, ``'bgr8'`` or ``'rgb8'``.

        Returns:
            The result; ``result.ok`` tells whether ``result.pose`` is set. Bad frames,
            lost boards and failed fits come back as a status with a reason.
        """
        try:
            stamp = float(stamp)
        except (TypeError, ValueError):
            stamp = math.nan
        try:
            gray, problem = self._to_gray(image, encoding)
            if gray is None:
                return _failure(stamp, TrackStatus.BAD_IMAGE, problem)
            if not math.isfinite(stamp):
                return _failure(stamp, TrackStatus.BAD_IMAGE, f'stamp {stamp!r} is not finite')
            if self._mismatch:
                return _failure(stamp, TrackStatus.RIG_MISMATCH, self._mismatch)
            exposure = self._check_exposure(gray)
            if exposure is not None:
                self.reset()
                return _failure(stamp, *exposure)
            return self._track(gray, stamp)
        except (cv2.error, np.linalg.LinAlgError, ValueError, FloatingPointError) as exc:
            # Corrupt data can drive OpenCV or the solver into an error; it is this frame's
            # problem, not the stream's.
            self.reset()
            return _failure(stamp, TrackStatus.BAD_IMAGE, f'{type(exc).__name__}: {exc}')

    def _to_gray(self, image: object, encoding: str) -> tuple[np.ndarray | None, str]:
        if encoding not in ENCODINGS:
            return None, f'encoding {encoding!r} is not one of {", ".join(ENCODINGS)}'
        if not isinstance(image, np.ndarray):
            return None, f'expected a numpy array, got {type(image).__name__}'
        if image.dtype != np.uint8:
            return None, f'expected uint8 pixels, got {image.dtype}'
        channels = 1 if encoding == 'mono8' else 3
        if image.ndim != (3 if channels == 3 else 2) or (channels == 3 and image.shape[2] != 3):
            return None, f'{encoding} image of shape {image.shape} has the wrong channels'
        try:
            self.camera_info.check_image_size(image.shape[1], image.shape[0], 'image')
        except LumpbeamError as exc:
            return None, str(exc)
        if channels == 3:
            code = cv2.COLOR_BGR2GRAY if encoding == 'bgr8' else cv2.COLOR_RGB2GRAY
            return cv2.cvtColor(image, code), ''
        return np.ascontiguousarray(image), ''

    def _check_exposure(self, gray: np.ndarray) -> tuple[TrackStatus, str] | None:
        # A sparse sample is plenty for grey-level statistics, and keeps this off the budget.
        step = max(1, int(math.sqrt(gray.size / 4096)))
        sample = gray[::step, ::step].reshape(-1)
        counts = np.bincount(sample, minlength=256)
        cumulative = np.cumsum(counts)
        low = int(np.searchsorted(cumulative, 0.01 * sample.size))
        high = int(np.searchsorted(cumulative, 0.99 * sample.size))
        saturated = counts[255] / sample.size
        if saturated > self.settings.max_saturated_fraction:
            return TrackStatus.SATURATED, f'{100 * saturated:.0f} % of the pixels are at 255'
        if high - low < self.settings.min_contrast_dn:
            return TrackStatus.TOO_DARK, (
                f'contrast {high - low} DN (1st to 99th percentile) is below '
                f'{self.settings.min_contrast_dn:g} DN'
            )
        return None

    def _predict(self, stamp: float) -> tuple[np.ndarray, np.ndarray] | None:
        """Constant-velocity prediction of the corners and the pose at ``stamp``."""
        if not self._history:
            return None
        t1, corners1, pose1 = self._history[-1]
        if stamp <= t1:
            return None
        if len(self._history) < 2:
            return corners1, pose1
        t0, corners0, pose0 = self._history[-2]
        ratio = (stamp - t1) / (t1 - t0)
        if ratio > 4.0:
            # After a gap the velocity is stale; the last position is the better guess.
            return corners1, pose1
        return corners1 + ratio * (corners1 - corners0), pose1 + ratio * (pose1 - pose0)

    def _verify(
        self, gray: np.ndarray, corners: np.ndarray, homography: bool = True
    ) -> tuple[np.ndarray | None, str]:
        """Returns the undistorted corners if they form a whole, consistent board.

        Args:
            gray: The frame.
            corners: Measured corners (N x 2).
            homography: Whether to fit a homography; once the rig is calibrated, the
                plane-constrained fit's per-corner residual is the same test, stricter.
        """
        if not np.all(np.isfinite(corners)):
            missing = int(np.sum(~np.all(np.isfinite(corners), axis=1)))
            return None, f'{missing} of {len(corners)} corners not found'
        contrast = corner_contrast(gray, corners, self._half_window)
        if np.min(contrast) < self.settings.min_contrast_dn:
            weak = int(np.sum(contrast < self.settings.min_contrast_dn))
            return None, f'{weak} corners show no checkerboard contrast (occluded?)'
        ideal = self.camera_info.undistort_pixels(corners)
        if not grid_is_regular(ideal, self._board.pattern_size):
            return None, 'corner grid is folded or irregular'
        residual = homography_residual(self._object_xy, ideal) if homography else 0.0
        if residual > self.settings.max_homography_residual_px:
            return None, f'corners miss a homography by {residual:.2f} px'
        return ideal, ''

    def _fit(self, ideal: np.ndarray, initial: np.ndarray) -> tuple[PoseFit | None, str]:
        model = self._free if self.pose_model == 'free' else self._model
        fit = model.fit(ideal, initial)
        if not fit.converged or not np.all(np.isfinite(fit.pose)):
            return None, f'{self.pose_model} pose fit did not converge'
        # Until the rig's fixed unknowns are estimated the model itself may be off by a few
        # pixels; the homography check has already vouched for the corners then.
        if self._is_calibrated():
            if fit.rms_px > self.settings.max_rms_px:
                return None, f'reprojection error {fit.rms_px:.2f} px exceeds the limit'
            if fit.max_px > self.settings.max_homography_residual_px:
                return None, f'a corner misses the fitted pose by {fit.max_px:.2f} px'
        return fit, ''

    def _track_prediction(
        self, gray: np.ndarray, stamp: float, guess: np.ndarray, pose_guess: np.ndarray
    ) -> tuple[TrackResult | None, str]:
        """Tracks from predicted corners, with those seen; the reason when too few are."""
        corners = refine_corners(gray, guess, self._half_window)
        pattern = self._board.pattern_size
        clean = self._clean_fit(gray, corners, guess, pose_guess)
        if clean is not None:
            # Every corner kept: what follows for a partial view has nothing to decide.
            result = self._accept(stamp, corners, *clean, detected=False)
            self._prediction_error = sorted_median(np.linalg.norm(corners - guess, axis=1))
            return result, ''
        selection = select_corners(
            gray, corners, guess, pattern, self._half_window, self.settings.min_contrast_dn,
            self._polarity,
        )  # fmt: skip
        ideal = np.full_like(corners, np.nan)
        ideal[selection.mask] = self.camera_info.undistort_pixels(corners[selection.mask])
        fit = self._fit_within_outlier_floor(ideal, selection.mask, pose_guess)
        mask = selection.mask
        if fit is None:
            mask = reject_outliers(self._object_xy, ideal, mask, self.settings.min_corners)
            selection = replace(selection, mask=mask, outliers=selection.count - int(mask.sum()))
        shortage = self._coverage_problem(mask)
        if shortage:
            # With no corner at all where the board should be, it is not a partial view.
            return None, f'{shortage} ({selection.describe()})' if mask.any() else ''
        error = sorted_median(np.linalg.norm(corners[mask] - guess[mask], axis=1))
        if not labelling_is_unambiguous(int(mask.sum()), pattern) and not (
            self._prediction_error <= self._half_window / 2
        ):
            # Few corners after a poor prediction may be neighbours caught one square off.
            return None, (
                f'partial view ({selection.describe()}) right after a detection or a poor '
                f'prediction ({self._prediction_error:.1f} px)'
            )
        ideal[~mask] = np.nan
        corners = np.where(mask[:, None], corners, np.nan)
        if fit is None:
            fit, _ = self._fit(ideal, pose_guess)
        if fit is None:
            return None, ''
        result = self._accept(stamp, corners, ideal, fit, detected=False)
        self._prediction_error = error
        return result, ''

    def _clean_fit(
        self, gray: np.ndarray, corners: np.ndarray, guess: np.ndarray, pose_guess: np.ndarray
    ) -> tuple[np.ndarray, PoseFit] | None:
        """The fit of every corner when the frame is clean, else ``None`` (the checks decide).

        Most frames show the whole board untouched, and the saddle check and the homography
        loop then keep every corner. They are left out when a cheaper screen says so: every
        corner refined, :func:`colours_as_expected` passing, and the calibrated pose model
        passing every corner within the residual check's own limit (:data:`OUTLIER_MEDIANS`
        times the median corner residual, at least :data:`OUTLIER_FLOOR_PX`), with the whole
        board meeting the documented minimum (it does but in an odd configuration). The model
        has fewer degrees of freedom than the check's homography, so a corner within that
        limit of it is within the limit of the homography too (up to the refit's share).
        When anything looks off the checks run as before, so partial views and occluders are
        handled exactly as without the screen.

        Args:
            gray: The frame.
            corners: The refined corners (N x 2; NaN where refinement failed).
            guess: The predicted corners (N x 2).
            pose_guess: The predicted pose.

        Returns:
            The undistorted corners and their fit, or ``None``.
        """
        if (
            not self._is_calibrated()
            or self._polarity is None
            or self._coverage_problem(np.ones(len(corners), dtype=bool))
            or not colours_as_expected(
                gray,
                corners,
                guess,
                self._board.pattern_size,
                self._half_window,
                self.settings.min_contrast_dn,
                self._polarity,
            )
        ):
            return None
        ideal = self.camera_info.undistort_pixels(corners)
        fit, _ = self._fit(ideal, pose_guess)
        if fit is None or not fit.max_px <= max(OUTLIER_FLOOR_PX, OUTLIER_MEDIANS * fit.median_px):
            return None
        return ideal, fit

    def _fit_within_outlier_floor(
        self, ideal: np.ndarray, mask: np.ndarray, pose_guess: np.ndarray
    ) -> PoseFit | None:
        """The fit of the selected corners when none of them can be an outlier, else ``None``.

        Once the rig is calibrated, the pose model is a homography with fewer degrees of
        freedom than :func:`reject_outliers`' own, so when it passes every corner within
        :data:`OUTLIER_FLOOR_PX` (a clean frame) no corner can miss the homography by more
        than that floor, and the homography loop is left out. Otherwise (an occluder, a
        corner caught off, or no calibration yet) the caller runs the loop as usual.

        Args:
            ideal: Undistorted corners (N x 2; NaN outside ``mask``).
            mask: The corners the saddle check kept.
            pose_guess: The predicted pose.

        Returns:
            The fit, or ``None`` when the homography loop must decide.
        """
        if not self._is_calibrated() or np.count_nonzero(mask) < max(self.settings.min_corners, 5):
            return None
        fit, _ = self._fit(np.where(mask[:, None], ideal, np.nan), pose_guess)
        if fit is None or not fit.max_px <= OUTLIER_FLOOR_PX:
            return None
        return fit

    def _coverage_problem(self, mask: np.ndarray) -> str:
        """:func:`coverage_problem` of the used corners (that of the whole board kept)."""
        if not mask.all():
            return self._coverage_of(mask)
        if self._whole_board_coverage is None:
            self._whole_board_coverage = self._coverage_of(mask)
        return self._whole_board_coverage

    def _coverage_of(self, mask: np.ndarray) -> str:
        return coverage_problem(
            self._object_xy, mask, self.settings.min_corners,
            self.settings.min_corner_spread, self._board.square_size_m,
        )  # fmt: skip

    def _track(self, gray: np.ndarray, stamp: float) -> TrackResult:
        prediction = self._predict(stamp)
        shortage = ''
        if prediction is None:
            self.reset()
        else:
            result, shortage = self._track_prediction(gray, stamp, *prediction)
            if result is not None:
                return result
        # Nothing to track, or tracking failed: search the whole frame.
        corners = detect_board(
            gray,
            self._board.pattern_size,
            self._expected_axes,
            self.settings.detect_max_side_px,
            self._half_window,
            # The free model's rig says nothing of the squares' size in the footage.
            snap_to_grid=self.pose_model == 'free',
        )
        if corners is None:
            self.reset()
            if shortage:
                return _failure(stamp, TrackStatus.TOO_FEW_CORNERS, shortage, detected=True)
            return _failure(
                stamp, TrackStatus.BOARD_NOT_FOUND, 'no complete checkerboard in the frame',
                detected=True,
            )  # fmt: skip
        corners = self._turned_by_colour(gray, corners)
        ideal, problem = self._verify(gray, corners)
        if ideal is None:
            self.reset()
            return _failure(
                stamp, TrackStatus.CORNERS_REJECTED, problem, corners=corners, detected=True
            )
        camera_board = solve_board_pnp(
            self._board.object_points(), ideal, self.camera_info, self._expected_rotation
        )
        if camera_board is None:
            self.reset()
            return _failure(
                stamp, TrackStatus.POSE_REJECTED, 'no valid PnP solution', corners=corners,
                detected=True,
            )  # fmt: skip
        if self._window_from_detection:
            self._half_window = self._window_for(corners)
        self._polarity = board_polarity(gray, corners, self._board.pattern_size, self._half_window)
        self._prediction_error = math.inf
        if self.pose_model == 'free':
            initial = free_pose_from_board_pose(self._model.rig, camera_board)
        else:
            initial = tip_pose_from_board_pose(self._model.rig, camera_board)
        fit, problem = self._fit(ideal, initial)
        if fit is None:
            self.reset()
            return _failure(
                stamp, TrackStatus.POSE_REJECTED, problem, corners=corners, detected=True
            )
        return self._accept(stamp, corners, ideal, fit, detected=True)

    def _turned_by_colour(self, gray: np.ndarray, corners: np.ndarray) -> np.ndarray:
        """The detected corners, labelled by the board's colours where the free model needs it.

        The detector's labelling follows the expected orientation, which the plane model's
        rig fixes but the free model's board, turned any way, does not: a board turned by
        some 90 degrees is as near one labelling as the other, 180 degrees apart, and a pose
        would come out turned by 180 degrees about the board's normal (a stereo pair then
        disagrees). When the colours tell the two apart, they decide.

        Args:
            gray: The frame.
            corners: The detected corners (N x 2, finite) in board order.

        Returns:
            ``corners``, or the same turned by 180 degrees (reversed).
        """
        board = self._board
        if self.pose_model != 'free' or not board.turn_swaps_colours:
            return corners
        polarity = board_polarity(gray, corners, board.pattern_size, self._half_window)
        if polarity == board.corner_polarity:
            return corners
        return np.ascontiguousarray(corners[::-1])

    def _accept(
        self,
        stamp: float,
        corners: np.ndarray,
        ideal: np.ndarray,
        fit: PoseFit,
        detected: bool,
    ) -> TrackResult:
        calibrated = self._is_calibrated()
        seen = np.all(np.isfinite(corners), axis=1)
        # Corners not seen are predicted from the pose, so the next frame looks for them.
        model = self._free if self.pose_model == 'free' else self._model
        filled = corners
        if not np.all(seen):
            projected = self.camera_info.project(model.camera_points(fit.pose))
            filled = np.where(seen[:, None], corners, projected)
        self._history = [*self._history[-1:], (stamp, filled, fit.pose)]
        if not calibrated and np.all(seen) and self._moved_since_last_pending(fit.pose):
            self._pending.append((ideal, fit.pose))
            if len(self._pending) >= self.settings.calibration_frames:
                self._calibrate()
            elif len(self._pending) == 1 and self.pose_model == 'plane':
                fit = self._calibrate_depth(ideal, fit)
            if self._mismatch:
                return _failure(
                    stamp, TrackStatus.RIG_MISMATCH, self._mismatch, corners=corners,
                    detected=detected,
                )  # fmt: skip
        pose, covariance, pose6, covariance6 = fit.pose, fit.covariance, None, None
        if self.pose_model == 'free':
            pose6, covariance6 = fit.pose, fit.covariance
            pose, covariance = planar_part(fit.pose, fit.covariance)
        return TrackResult(
            stamp,
            TrackStatus.OK,
            pose=pose,
            covariance=covariance,
            rms_px=fit.rms_px,
            corners=corners,
            detected=detected,
            calibrated=calibrated,
            corners_used=int(np.count_nonzero(seen)),
            pose6=pose6,
            covariance6=covariance6,
        )

    def _moved_since_last_pending(self, pose: np.ndarray) -> bool:
        if not self._pending:
            return True
        step = np.max(np.abs(pose[:2] - self._pending[-1][1][:2]))
        return bool(step >= self.settings.calibration_min_step_m)

    def _is_calibrated(self) -> bool:
        return (
            self._calibration is not None
            or self.settings.calibration_frames == 0
            or self.pose_model == 'free'
        )

    def _calibrate_depth(self, ideal: np.ndarray, fit: PoseFit) -> PoseFit:
        """Corrects the board's distance from the first frame, before the full calibration.

        The board's known squares fix the distance in a single frame, and a configured
        distance 5 mm off would otherwise bias the tip by some 300 um (the scale error times
        the tip's offset from the board's centre) until the full calibration is done.

        Args:
            ideal: The frame's undistorted corners.
            fit: Its fit with the configured rig.

        Returns:
            The frame's fit with the corrected rig (``fit`` when the correction fails).
        """
        try:
            early = calibrate_rig(
                self.config.rig, self.camera_info, [ideal], [fit.pose],
                self.settings.tilt_prior_std_rad,
            )  # fmt: skip
        except LumpbeamError:
            return fit
        self._set_rig(early.rig)
        self._check_distance()
        refit = self._model.fit(ideal, fit.pose)
        if not refit.converged:
            return fit
        self._history[-1] = (self._history[-1][0], self._history[-1][1], refit.pose)
        self._pending[-1] = (ideal, refit.pose)
        return refit

    def _check_distance(self) -> None:
        """Refuses the footage when the board's squares put it far from where it is configured.

        The squares' known size gives the board's distance (the calibration's depth); the
        tip's in-plane pose scales with it. A board of another square size than the
        configured one (or a rig measured that far off) would give every pose scaled by
        the ratio: a 50 mm square taken for 60 mm moved the tip by 7.7 mm.
        """
        configured, seen = self._configured_distance_m, self._board_distance_m
        limit = self.settings.max_depth_correction
        if abs(seen / configured - 1.0) > limit:
            self._mismatch = (
                f"the board's squares put it {seen:.3f} m from the camera, the configuration "
                f'{configured:.3f} m (more than {100 * limit:g} % apart): a board of another '
                f'square size than {self._board.square_size_m:g} m, or the rig measured wrong; '
                'every frame is refused'
            )

    def _calibrate(self) -> None:
        pixels = [p for p, _ in self._pending]
        poses = [q for _, q in self._pending]
        self._pending = []
        try:
            calibration = calibrate_rig(
                self.config.rig, self.camera_info, pixels, poses,
                self.settings.tilt_prior_std_rad,
            )  # fmt: skip
        except LumpbeamError:
            return  # keep the configured rig and try again with the next frames
        self._calibration = calibration
        self._set_rig(calibration.rig)
        self._check_distance()
        # The last pose was fitted with the old rig; re-fit it so the velocity is consistent.
        t1, corners1, _ = self._history[-1]
        refit = self._model.fit(pixels[-1], poses[-1])
        self._history = [(t1, corners1, refit.pose)]
