import dataclasses

import cv2
import numpy as np
import pytest

from lumpbeam_ros.vision.accuracy import render_frames, tracker_config
from lumpbeam_ros.vision.pose import PlaneModel
from lumpbeam_ros.vision.tracker import TipTracker, TrackStatus


@pytest.fixture(scope='module')
def frames(config, drop_test):
    # Across the release, where the tip starts moving fastest.
    return render_frames(config, drop_test.between(1.95, 2.3), 30)


@pytest.fixture
def tracker(config, no_calibration):
    return TipTracker(config.camera_info, no_calibration)


def test_detects_once_then_tracks(tracker, frames):
    results = [tracker.process(f.image, f.stamp) for f in frames]
    assert all(r.ok for r in results)
    assert results[0].detected and not any(r.detected for r in results[1:])
    errors = np.array([r.pose - f.truth for r, f in zip(results, frames, strict=True)])
    assert np.max(np.abs(errors[:, 1])) < 20e-6
    assert all(r.covariance.shape == (3, 3) and r.rms_px < 0.1 for r in results)


def _bad_frames(frame, config):
    h, w = frame.image.shape
    # Only the first column of corners left in view: 6 corners, along a line.
    corners = PlaneModel(config.rig, config.camera_info).project(frame.truth)
    occluded = frame.image.copy()
    occluded[:, int(corners[0, 0]) + 20 :] = 110
    return {
        'float image': (frame.image.astype(np.float32), TrackStatus.BAD_IMAGE),
        'wrong size': (frame.image[:-2], TrackStatus.BAD_IMAGE),
        'not an array': ([[1, 2], [3, 4]], TrackStatus.BAD_IMAGE),
        'black': (np.zeros_like(frame.image), TrackStatus.TOO_DARK),
        'saturated': (np.full_like(frame.image, 255), TrackStatus.SATURATED),
        'occluded': (occluded, TrackStatus.TOO_FEW_CORNERS),
        'noise': (
            np.random.default_rng(1).integers(0, 256, frame.image.shape, dtype=np.uint8),
            TrackStatus.BOARD_NOT_FOUND,
        ),
    }


@pytest.mark.parametrize(
    'case',
    ['float image', 'wrong size', 'not an array', 'black', 'saturated', 'occluded', 'noise'],
)  # fmt: skip
def test_bad_frame_gives_a_status_and_no_stale_pose(tracker, frames, config, case):
    for f in frames[:3]:
        assert tracker.process(f.image, f.stamp).ok
    image, status = _bad_frames(frames[3], config)[case]
    result = tracker.process(image, frames[3].stamp)
    assert result.status is status
    assert result.pose is None and result.covariance is None
    assert result.reason
    if case == 'wrong size':
        assert (
            result.reason
            == 'camera info: calibrated for 640 x 480 px but the image is 640 x 478 px'
        )

    # The stream recovers on the next good frame.
    following = tracker.process(frames[4].image, frames[4].stamp)
    assert following.ok
    assert abs(following.pose[1] - frames[4].truth[1]) < 20e-6


@pytest.mark.parametrize('stamp', [float('nan'), 'soon', None])
def test_bad_stamp(tracker, frames, stamp):
    result = tracker.process(frames[0].image, stamp)
    assert result.status is TrackStatus.BAD_IMAGE and result.pose is None


@pytest.mark.parametrize(('encoding', 'code'), [('bgr8', cv2.COLOR_GRAY2BGR), ('rgb8', None)])
def test_colour_encodings(tracker, frames, encoding, code):
    colour = cv2.cvtColor(frames[0].image, cv2.COLOR_GRAY2BGR)
    result = tracker.process(colour, frames[0].stamp, encoding=encoding)
    assert result.ok
    wrong = tracker.process(colour, frames[1].stamp, encoding='mono8')
    assert wrong.status is TrackStatus.BAD_IMAGE
    unknown = tracker.process(frames[1].image, frames[1].stamp, encoding='yuv422')
    assert unknown.status is TrackStatus.BAD_IMAGE and 'yuv422' in unknown.reason


def test_stamp_going_backwards_redetects(tracker, frames):
    tracker.process(frames[5].image, frames[5].stamp)
    tracker.process(frames[6].image, frames[6].stamp)
    result = tracker.process(frames[2].image, frames[2].stamp)
    assert result.ok and result.detected
    assert abs(result.pose[1] - frames[2].truth[1]) < 20e-6


def test_calibration_phase_then_calibrated(config, frames):
    """Only frames that moved 1 mm since the last one joined calibrate (not the beam at rest)."""
    believed = dataclasses.replace(
        config, tracker=dataclasses.replace(config.tracker, calibration_frames=10)
    )
    tracker = TipTracker(config.camera_info, believed)
    results = [tracker.process(f.image, f.stamp) for f in frames]
    joined, last = [], None
    for i, f in enumerate(frames):
        if last is None or np.max(np.abs(f.truth[:2] - last)) >= 0.001:
            joined.append(i)
            last = f.truth[:2]
    done = joined[9]  # the 10th joining frame completes the calibration
    assert done > 15  # the 9 frames at rest before the release count once
    assert [r.calibrated for r in results] == [i > done for i in range(len(frames))]
    assert tracker.calibration is not None and tracker.calibration.frames == 10


def test_a_beam_at_rest_never_calibrates(config, frames):
    believed = dataclasses.replace(
        config, tracker=dataclasses.replace(config.tracker, calibration_frames=3)
    )
    tracker = TipTracker(config.camera_info, believed)
    for i in range(8):
        assert tracker.process(frames[0].image, frames[0].stamp + i).ok
    assert tracker.calibration is None


def test_a_wrong_board_distance_is_corrected_from_the_first_frame(config, frames):
    """A board 5 mm off its configured depth is corrected on the first frame.

    Before, every pose until the full calibration was biased by some 100 um (the scale
    error times the tip's offset from the board's centre).
    """
    tracker = TipTracker(config.camera_info, tracker_config(config, (0.0, 0.0, 0.005)))
    results = [tracker.process(f.image, f.stamp) for f in frames[:5]]
    assert all(r.ok and not r.calibrated for r in results)
    errors = np.array([r.pose - f.truth for r, f in zip(results, frames[:5], strict=True)])
    assert np.max(np.abs(errors[:, :2])) < 20e-6
