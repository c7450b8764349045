import dataclasses

import numpy as np
import pytest

from lumpbeam_ros.core.bagio import TipSeries
from lumpbeam_ros.core.model.trajectory import TipTrajectory

T = np.arange(10) * 0.5


def _series():
    return TipSeries(T, T + 2.0, -T, T / 100.0, frame_id='world')


@pytest.mark.parametrize(
    ('start', 'end', 'expected'),
    [(1.0, 2.0, [1.0, 1.5]), (-1.0, 0.5, [0.0]), (4.5, 9.0, [4.5]), (3.0, 3.0, [])],
)
def test_between_keeps_start_up_to_but_not_end(start, end, expected):
    part = _series().between(start, end)
    np.testing.assert_array_equal(part.t, expected)
    np.testing.assert_array_equal(part.x, np.asarray(expected) + 2.0)
    np.testing.assert_array_equal(part.z, -np.asarray(expected))
    np.testing.assert_array_equal(part.pitch, np.asarray(expected) / 100.0)
    assert part.frame_id == 'world' and len(part) == len(expected)


def test_start_end_and_an_empty_series():
    assert (_series().start_s, _series().end_s) == (0.0, 4.5)
    empty = _series().between(10.0, 11.0)
    assert len(empty) == 0 and np.isnan(empty.start_s) and np.isnan(empty.end_s)


def test_vertical_motion_has_no_x():
    series = TipSeries.vertical(T, -T, T * 0.0)
    assert series.frame_id == 'beam_base' and np.isnan(series.x).all() and len(series) == 10


def test_a_trajectory_is_a_tip_series_and_cuts_its_own_arrays():
    q = np.column_stack([T, 2 * T])
    trajectory = TipTrajectory(T, T, -T, T, T * 0 + 4.5, q)
    assert isinstance(trajectory, TipSeries)
    part = trajectory.between(1.0, 2.0)
    assert type(part) is TipTrajectory
    np.testing.assert_array_equal(part.load_kg, [4.5, 4.5])
    np.testing.assert_array_equal(part.q, [[1.0, 2.0], [1.5, 3.0]])
    assert part.between(0.0, 1.2).q.shape == (1, 2)
    # Arrays not sized per sample (none here) and scalars pass unchanged.
    assert dataclasses.replace(trajectory, q=None).between(0.0, 1.0).q is None


def test_the_series_is_frozen():
    with pytest.raises(dataclasses.FrozenInstanceError):
        _series().t = T  # type: ignore[misc]


def test_clean_tip_series_drops_sorts_and_counts():
    from lumpbeam_ros.core.bagio.tipseries import SampleCounts, clean_tip_series

    t = np.array([0.3, 0.1, np.nan, 0.2, 0.2, 0.4, 0.5])
    z = np.array([3.0, 1.0, 9.0, 2.0, 7.0, np.inf, 5.0])
    pitch = np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, np.nan])
    trajectory = TipTrajectory(t, t + 2.0, z, pitch, np.full(7, 4.5), None, frame_id='f')
    cleaned, counts = clean_tip_series(trajectory)
    assert type(cleaned) is TipTrajectory and cleaned.frame_id == 'f'
    np.testing.assert_array_equal(cleaned.t, [0.1, 0.2, 0.3])
    np.testing.assert_array_equal(cleaned.z, [1.0, 2.0, 3.0])  # the first of stamp 0.2
    np.testing.assert_array_equal(cleaned.x, cleaned.t + 2.0)
    np.testing.assert_array_equal(cleaned.load_kg, [4.5] * 3)
    assert counts == SampleCounts(received=7, non_finite=3, duplicates=1, reordered=True)
    assert counts.kept == 3
    assert counts.note() == (
        'dropped 4 of 7 poses (3 with a NaN or inf stamp, position or orientation; '
        '1 with a repeated or out-of-order stamp); stamps out of order: sorted'
    )
    # A sensor without pitch: a NaN pitch keeps the sample.
    _, counts = clean_tip_series(TipSeries(t, t, z, pitch), pitch_required=False)
    assert counts.non_finite == 2


def test_clean_tip_series_of_clean_poses_changes_nothing():
    from lumpbeam_ros.core.bagio.tipseries import SampleCounts, clean_tip_series

    series = _series()
    cleaned, counts = clean_tip_series(series)
    assert counts == SampleCounts(received=10) and counts.note() == ''
    np.testing.assert_array_equal(cleaned.t, series.t)
