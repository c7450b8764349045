import numpy as np
import pytest

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.compare.streams import MIN_SAMPLES, GapInterpolator, clean_track


def _line(n=50, rate=100.0):
    t = np.arange(n) / rate
    points = np.column_stack([t, 2.0 * t, -t])  # moves at (1, 2, -1) m/s
    return t, points


@pytest.mark.parametrize(
    ('t_edit', 'p_edit', 'kept'),
    [
        ({}, {}, 50),
        ({3: np.nan}, {}, 49),
        ({}, {(7, 1): np.inf}, 49),
        ({4: 0.03}, {}, 49),  # duplicate of stamp 3: the first one stays
    ],
)
def test_clean_track_drops_bad_samples(t_edit, p_edit, kept):
    t, points = _line()
    for i, v in t_edit.items():
        t[i] = v
    for ij, v in p_edit.items():
        points[ij] = v
    track = clean_track(t[::-1], points[::-1], 'tracker', '/tracker/point')
    assert len(track) == kept
    assert np.all(np.diff(track.t) > 0.0)
    assert np.all(np.isfinite(track.points))


@pytest.mark.parametrize(
    ('n', 'shape', 'message'),
    [
        (MIN_SAMPLES - 1, None, 'need at least'),
        (30, (30, 2), 'expected 30 x 3'),
    ],
)
def test_clean_track_rejects(n, shape, message):
    t = np.arange(n, dtype=float)
    points = np.zeros(shape or (n, 3))
    with pytest.raises(LumpbeamError, match=message):
        clean_track(t, points, 'tracker', '/tracker/point')


def test_interpolation_and_velocity_of_a_line():
    t, points = _line()
    interp = GapInterpolator(clean_track(t, points, 'f', 'src'))
    query = np.array([0.005, 0.1234, 0.3])
    assert np.allclose(interp(query)[:, 1], 2.0 * query)
    assert np.allclose(interp.velocity(query, 0.002), [1.0, 2.0, -1.0])
    assert interp.gap_count == 0


@pytest.mark.parametrize(
    ('query', 'margin', 'valid'),
    [
        (0.095, 0.0, True),  # between two samples before the gap
        (0.13, 0.0, False),  # inside the gap 0.10..0.20
        (0.205, 0.0, True),
        (0.205, 0.01, False),  # too close to the gap's end
        (0.085, 0.01, True),
        (0.095, 0.01, False),  # too close to its start
        (-0.001, 0.0, False),  # before the track
        (0.49, 0.0, True),
        (0.485, 0.01, False),  # near the end with a margin
    ],
)
def test_gaps_are_not_bridged(query, margin, valid):
    t, points = _line()
    keep = (t <= 0.1 + 1e-9) | (t >= 0.2 - 1e-9)
    interp = GapInterpolator(clean_track(t[keep], points[keep], 'f', 'src'))
    assert interp.gap_count == 1
    assert bool(interp.valid(np.array([query]), margin)[0]) is valid


def test_a_single_dropped_sample_is_bridged():
    t, points = _line()
    keep = np.ones(t.size, bool)
    keep[10] = False
    interp = GapInterpolator(clean_track(t[keep], points[keep], 'f', 'src'))
    assert interp.gap_count == 0
    assert interp.valid(np.array([0.1]))[0]
