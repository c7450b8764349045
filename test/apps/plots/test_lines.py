"""Lines broken at the gaps of their samples."""

import numpy as np

from lumpbeam_ros.apps.plots.lines import broken_at_gaps


def test_a_gap_gets_a_nan_and_the_rest_is_kept():
    t = np.array([0.0, 0.1, 0.2, 0.3, 1.0, 1.1])
    y = np.arange(6.0)
    bt, by = broken_at_gaps(t, y)
    assert bt.tolist()[:5] == [0.0, 0.1, 0.2, 0.3, 0.65] and np.isnan(by[4])
    assert np.array_equal(by[~np.isnan(by)], y) and np.all(np.diff(bt) > 0)


def test_samples_without_a_gap_are_returned_as_they_are():
    t = np.linspace(0.0, 1.0, 11)
    assert np.array_equal(broken_at_gaps(t, t)[1], t)
    assert broken_at_gaps(t[:2], t[:2])[0].size == 2
