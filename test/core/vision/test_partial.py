"""Partial views: the board sliding out of the image, cables and hands in front of it.

Run with ``-s`` to see the figures: per scenario, the RMS error with the bias in it (bias,
std, max beside it) over every published pose, and the median sigma the tracker claims.
"""

import cv2
import numpy as np
import pytest

from lumpbeam_ros.core.vision import tracker as tracker_module
from lumpbeam_ros.core.vision.corners import refine_corners
from lumpbeam_ros.core.vision.partial import (
    MAX_SADDLE_MISFIT,
    MISFIT_CEILING,
    MISFIT_MEDIANS,
    board_polarity,
    checked_saddle_fit,
    colours_as_expected,
    coverage_problem,
    grid_axes,
    labelling_is_unambiguous,
    reject_outliers,
    saddle_fit,
    select_corners,
)
from lumpbeam_ros.core.vision.pose import PlaneModel
from lumpbeam_ros.core.vision.session import TrackingSession
from lumpbeam_ros.core.vision.synthetic import SyntheticCamera
from lumpbeam_ros.core.vision.tracker import TipTracker, TrackStatus

# The 640 x 480 set-up resolves z to about 20 um (test_accuracy); a corner a whole square
# off would be 60 mm.
Z_LIMIT_M = 60e-6
PITCH_LIMIT_RAD = 0.3e-3


def _figures(name, results, truths):
    used = [(r, t) for r, t in zip(results, truths, strict=True) if r.ok]
    error = np.array([r.pose - t for r, t in used])
    sigma = np.median([np.sqrt(np.diag(r.covariance)) for r, _ in used], axis=0)
    rms = np.sqrt(np.mean(error**2, axis=0))
    corners = [r.corners_used for r, _ in used]
    print(
        f'{name:>12}: {len(used)} poses ({min(corners)}-{max(corners)} corners), '
        f'z rms {rms[1] * 1e6:.1f} um (bias {error[:, 1].mean() * 1e6:.1f}, std '
        f'{error[:, 1].std() * 1e6:.1f}, max {np.abs(error[:, 1]).max() * 1e6:.1f}), '
        f'x rms {rms[0] * 1e6:.1f} um, pitch rms {rms[2] * 1e3:.4f} mrad (max '
        f'{np.abs(error[:, 2]).max() * 1e3:.4f}); median sigma z {sigma[1] * 1e6:.2f} um, '
        f'pitch {sigma[2] * 1e3:.4f} mrad'
    )
    return error, sigma


@pytest.fixture(scope='module')
def sliding(config):
    """The tip moving 0.55 m along x at constant speed: the board slides out to the left."""
    t = np.arange(100) / 180.0
    x = 2.3107 + 0.55 * t / t[-1]
    frames = list(
        SyntheticCamera(config).render_trajectory(
            t, x, np.full_like(t, -0.012), np.full_like(t, 0.004)
        )
    )
    return frames


def test_board_sliding_out_of_view(no_calibration, sliding):
    tracker = TipTracker(no_calibration.camera_info, no_calibration)
    results = [tracker.process(f.image, f.stamp) for f in sliding]
    truths = [f.truth for f in sliding]
    full = [i for i, r in enumerate(results) if r.ok and r.corners_used == 48]
    partial = [i for i, r in enumerate(results) if r.ok and r.corners_used < 48]
    print()
    _, sigma_full = _figures('full view', [results[i] for i in full], [truths[i] for i in full])
    error, sigma_partial = _figures(
        'out of view', [results[i] for i in partial], [truths[i] for i in partial]
    )
    assert full and len(partial) >= 20
    assert min(results[i].corners_used for i in partial) <= 18
    assert np.max(np.abs(error[:, 1])) < Z_LIMIT_M
    assert np.max(np.abs(error[:, 2])) < PITCH_LIMIT_RAD
    # Fewer corners, larger claimed uncertainty.
    assert sigma_partial[1] > 1.2 * sigma_full[1] and sigma_partial[2] > 1.5 * sigma_full[2]
    fewest = min(partial, key=lambda i: results[i].corners_used)
    assert np.sqrt(results[fewest].covariance[2, 2]) > 2.0 * sigma_full[2]
    # Past the minimum: no pose, and the reason says why.
    gone = [r for r in results[partial[-1] + 1 :]]
    assert gone and all(not r.ok and r.pose is None for r in gone)
    assert gone[0].status is TrackStatus.TOO_FEW_CORNERS
    assert 'corners seen' in gone[0].reason


def _bar(image, point, angle, width, value, half_length=2000.0):
    direction = np.array([np.cos(angle), np.sin(angle)])
    a = np.asarray(point) - half_length * direction
    b = np.asarray(point) + half_length * direction
    out = image.copy()
    cv2.line(out, tuple(int(v) for v in a), tuple(int(v) for v in b), int(value), int(width))
    return out


def _blob(image, centre, axes, value):
    out = image.copy()
    cv2.ellipse(out, tuple(int(v) for v in centre), axes, 30.0, 0.0, 360.0, int(value), -1)
    return out


@pytest.fixture(scope='module')
def drop_frames(config, drop_test):
    from lumpbeam_lab.camera.accuracy import render_frames

    return render_frames(config, drop_test.between(1.95, 2.3), 40)


def _occluders(frame, config):
    corners = PlaneModel(config.rig, config.camera_info).project(frame.truth)
    centre = corners.mean(axis=0)
    return {
        'cable': _bar(frame.image, centre, 1.1, 6, 25),
        'grey cable': _bar(frame.image, corners[19] + [3.0, 0.0], 1.45, 3, 120),
        'hand': _blob(frame.image, corners[40], (110, 70), 160),
        # The edge of a dark sheet running 1.5 px from a row of corners.
        'edge': _bar(frame.image, corners[17] + [0.0, -1.5 - 60.0], 0.0, 120, 20),
    }


@pytest.mark.parametrize('kind', ['cable', 'grey cable', 'hand', 'edge'])
def test_occluders_drop_corners_not_accuracy(config, no_calibration, drop_frames, kind):
    """From frame 5 on, an occluder: poses stay within tolerance and claim more sigma."""
    tracker = TipTracker(no_calibration.camera_info, no_calibration)
    clean = TipTracker(no_calibration.camera_info, no_calibration)
    results, reference = [], []
    for i, f in enumerate(drop_frames):
        image = _occluders(f, config)[kind] if i >= 5 else f.image
        results.append(tracker.process(image, f.stamp))
        reference.append(clean.process(f.image, f.stamp))
    occluded = results[5:]
    assert all(r.ok for r in occluded)
    assert all(r.corners_used < 48 for r in occluded)
    error, sigma = _figures(kind, occluded, [f.truth for f in drop_frames[5:]])
    _, sigma_clean = _figures('no occluder', reference[5:], [f.truth for f in drop_frames[5:]])
    assert np.max(np.abs(error[:, 1])) < Z_LIMIT_M
    assert np.max(np.abs(error[:, 2])) < PITCH_LIMIT_RAD
    # The occluder changes the pose by no more than the corners it took away allow.
    shift = np.array([r.pose - c.pose for r, c in zip(occluded, reference[5:], strict=True)])
    assert np.all(
        np.abs(shift[:, 1]) < 4 * np.array([np.sqrt(r.covariance[1, 1]) for r in occluded])
    )
    assert sigma[1] >= sigma_clean[1] * 0.9


def test_a_hand_over_most_of_the_board_gives_no_pose_and_a_reason(
    config, no_calibration, drop_frames
):
    session = TrackingSession(no_calibration, no_calibration.camera_info)
    for f in drop_frames[:3]:
        assert session.process(f.image, f.stamp).ok
    f = drop_frames[3]
    corners = PlaneModel(config.rig, config.camera_info).project(f.truth)
    image = _blob(f.image, corners.mean(axis=0) + [40, 0], (190, 150), 160)
    result = session.process(image, f.stamp)
    assert result.status is TrackStatus.TOO_FEW_CORNERS and result.pose is None
    assert 'need 12' in result.reason
    assert session.stats.lost['too_few_corners'] == 1


@pytest.mark.parametrize('angle', np.linspace(0.0, np.pi, 6, endpoint=False))
def test_an_edge_across_a_corner_never_biases_it(config, angle):
    """Bars of every grey level and width through one corner: it is dropped or unbiased."""
    image = SyntheticCamera(config).render(np.array([2.3107, -0.012, 0.004]))
    truth = PlaneModel(config.rig, config.camera_info).project(np.array([2.3107, -0.012, 0.004]))
    object_xy = config.rig.board.object_points()[:, :2]
    pattern = config.rig.board.pattern_size
    k, kept, dropped = 20, 0, 0
    normal = np.array([-np.sin(angle), np.cos(angle)])
    for offset in np.arange(-12.0, 12.5, 1.0):
        for width, value in ((2, 20), (4, 110), (6, 240), (3, 160)):
            painted = _bar(image, truth[k] + offset * normal, angle, width, value)
            refined = refine_corners(painted, truth + 0.3, 5)
            selection = select_corners(painted, refined, truth, pattern, 5, 20.0)
            mask = reject_outliers(object_xy, refined, selection.mask, 12)
            if mask[k]:
                kept += 1
                assert np.linalg.norm(refined[k] - truth[k]) < 0.2, (offset, width, value)
            else:
                dropped += 1
    assert dropped > 0 and kept > 0


@pytest.mark.parametrize(
    ('blur', 'noise'), [(0.0, 0.0), (0.8, 0.0), (1.6, 0.0), (0.0, 10.0), (0.8, 4.0)]
)  # fmt: skip
def test_the_staged_blur_search_decides_as_the_full_one(config, blur, noise):
    """Sharp, defocused and noisy frames with bars over the board: the same corners pass."""
    pose = np.array([2.3107, -0.012, 0.004])
    truth = PlaneModel(config.rig, config.camera_info).project(pose)
    pattern = config.rig.board.pattern_size
    along_x, along_y = grid_axes(truth, pattern)
    rng = np.random.default_rng(3)
    image = SyntheticCamera(config).render(pose)
    if blur:
        image = cv2.GaussianBlur(image, (0, 0), blur)
    # Bars of any grey level, width and angle, near or through a few corners.
    for k in (3, 12, 20, 29, 33, 42):
        offset, angle = rng.uniform(-5.0, 5.0, 2), rng.uniform(0.0, np.pi)
        width, value = rng.integers(1, 5), rng.integers(0, 256)
        image = _bar(image, truth[k] + offset, angle, width, value)
    if noise:
        image = np.clip(image + rng.normal(0.0, noise, image.shape), 0, 255).astype(np.uint8)
    refined = refine_corners(image, truth + 0.3, 5)
    misfits, decisions = [], []
    for fit in (saddle_fit, checked_saddle_fit):
        _, misfit = fit(image, refined, along_x, along_y, 7)
        median = MISFIT_MEDIANS * float(np.median(misfit))
        limit = min(max(MAX_SADDLE_MISFIT, median), MISFIT_CEILING)
        misfits.append(misfit)
        decisions.append(misfit <= limit)
    full, staged = misfits
    np.testing.assert_array_equal(decisions[0], decisions[1])
    # Why they agree: a misfit kept from the first blur is never better than the best one,
    # is within the limit's floor, and leaves the median below where it raises the limit
    # or every misfit within the floor.
    assert np.all(staged >= full - 1e-12)
    differ = staged > full + 1e-12
    assert np.all(staged[differ] <= MAX_SADDLE_MISFIT)
    assert (
        not np.any(differ)
        or np.median(staged) <= MAX_SADDLE_MISFIT / MISFIT_MEDIANS
        or np.all(staged <= MAX_SADDLE_MISFIT)
    )
    assert 0 < np.count_nonzero(decisions[0]) < 48


def test_clean_corners_all_pass(config, rest_pose):
    image = SyntheticCamera(config).render(rest_pose)
    truth = PlaneModel(config.rig, config.camera_info).project(rest_pose)
    refined = refine_corners(image, truth + 0.5, 5)
    selection = select_corners(image, refined, truth, config.rig.board.pattern_size, 5, 20.0)
    assert selection.count == 48 and selection.describe() == '48 of 48 corners'
    # The wrong colour order (a labelling one square off) passes none.
    wrong = select_corners(image, refined, truth, config.rig.board.pattern_size, 5, 20.0, -1.0)
    right = select_corners(image, refined, truth, config.rig.board.pattern_size, 5, 20.0, 1.0)
    assert {wrong.count, right.count} == {0, 48}


def test_the_colour_screen_passes_a_clean_board_only(config, drop_frames):
    """Right colours pass; the wrong order, a pale frame and every occluder fail."""
    frame = drop_frames[10]
    truth = PlaneModel(config.rig, config.camera_info).project(frame.truth)
    pattern = config.rig.board.pattern_size

    def screen(image, polarity):
        refined = refine_corners(image, truth + 0.3, 5)
        return colours_as_expected(image, refined, truth, pattern, 5, 20.0, polarity)

    polarity = board_polarity(frame.image, truth, pattern, 5)
    assert screen(frame.image, polarity)
    assert not screen(frame.image, -polarity)
    pale = (frame.image * 0.08 + 110).astype(np.uint8)  # 15 DN between the squares
    assert not screen(pale, polarity)
    for kind, image in _occluders(frame, config).items():
        assert not screen(image, polarity), kind


def test_the_clean_frame_screen_changes_no_pose(no_calibration, drop_frames, monkeypatch):
    """With the screen, clean frames give the very poses the saddle and residual checks give."""
    passed = []

    def counted(*args):
        passed.append(colours_as_expected(*args))
        return passed[-1]

    monkeypatch.setattr(tracker_module, 'colours_as_expected', counted)
    tracker = TipTracker(no_calibration.camera_info, no_calibration)
    screened = [tracker.process(f.image, f.stamp) for f in drop_frames]
    monkeypatch.setattr(tracker_module, 'colours_as_expected', lambda *args: False)
    tracker = TipTracker(no_calibration.camera_info, no_calibration)
    checked = [tracker.process(f.image, f.stamp) for f in drop_frames]
    assert sum(passed) >= len(drop_frames) - 2  # all but the detection frame (and one)
    for a, b in zip(screened, checked, strict=True):
        assert a.ok and b.ok and a.corners_used == b.corners_used == 48
        np.testing.assert_array_equal(a.pose, b.pose)
        np.testing.assert_array_equal(a.covariance, b.covariance)


def test_grid_axes_are_one_square(config, rest_pose):
    truth = PlaneModel(config.rig, config.camera_info).project(rest_pose)
    along_x, along_y = grid_axes(truth, config.rig.board.pattern_size)
    np.testing.assert_allclose(along_x[9], truth[10] - truth[9], atol=0.5)
    np.testing.assert_allclose(along_y[9], truth[17] - truth[9], atol=0.5)


@pytest.mark.parametrize(
    ('rows', 'cols', 'ok'),
    [
        ((0, 6), (0, 8), True),  # whole board
        ((0, 2), (0, 6), True),  # two full rows and six columns: 12 corners, spread 0.5
        ((0, 3), (0, 4), True),  # a 4 x 3 block
        ((0, 1), (0, 8), False),  # one row: a line
        ((0, 2), (0, 5), False),  # 10 corners
    ],
)
def test_documented_minimum(config, rows, cols, ok):
    board = config.rig.board
    mask = np.zeros((6, 8), dtype=bool)
    mask[rows[0] : rows[1], cols[0] : cols[1]] = True
    object_xy = board.object_points()[:, :2]
    problem = coverage_problem(object_xy, mask.ravel(), 12, 0.5, board.square_size_m)
    assert (problem == '') == ok, problem
    diagonal = np.eye(6, 8, dtype=bool) | np.eye(6, 8, 1, dtype=bool)
    assert 'line' in coverage_problem(object_xy, diagonal.ravel(), 12, 0.5, 0.06)


def test_shifted_labellings_cannot_find_as_many_corners():
    assert labelling_is_unambiguous(43, (8, 6)) and not labelling_is_unambiguous(42, (8, 6))


@pytest.mark.parametrize('pattern', [(8, 6), (5, 1), (1, 4), (2, 2)])
def test_grid_axes_are_numpys_gradient(pattern):
    cols, rows = pattern
    grid = np.random.default_rng(5).uniform(0.0, 500.0, (cols * rows, 2))
    along_x, along_y = grid_axes(grid, pattern)
    g = grid.reshape(rows, cols, 2)
    for axis, along, n in ((1, along_x, cols), (0, along_y, rows)):
        expected = np.gradient(g, axis=axis) if n > 1 else np.zeros_like(g)
        np.testing.assert_array_equal(along, expected.reshape(-1, 2))


def test_saddle_fit_is_the_same_at_the_image_border(config, rest_pose):
    """A window clipped by the border is read as before, only the gather differs."""
    image = SyntheticCamera(config).render(rest_pose)
    truth = PlaneModel(config.rig, config.camera_info).project(rest_pose)
    along_x, along_y = grid_axes(truth, config.rig.board.pattern_size)
    x0, y0 = np.floor(truth[0]).astype(int) - 3
    # The same pixels, with corner 0 three pixels from the top-left border of a crop.
    crop = np.ascontiguousarray(image[y0:, x0:])
    shifted = truth - [x0, y0]
    assert x0 > 0 and y0 > 0
    whole = saddle_fit(image, truth[:1], along_x[:1], along_y[:1], 7)
    clipped = saddle_fit(crop, shifted[:1], along_x[:1], along_y[:1], 7)
    # Corner 18 (row 2, column 2) is well inside the crop.
    k = slice(18, 19)
    inside = saddle_fit(crop, shifted[k], along_x[k], along_y[k], 7)
    np.testing.assert_allclose(inside, saddle_fit(image, truth[k], along_x[k], along_y[k], 7))
    # The clipped window repeats its edge pixels, so it cannot match the whole one exactly.
    assert np.all(np.isfinite(clipped[1])) and not np.allclose(clipped[1], whole[1])
