import numpy as np
import pytest

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.samples import clean_loads, clean_window


def test_clean_window_drops_sorts_and_dedups():
    t = [0.3, 0.1, 0.2, 0.2, np.nan, 0.4, 0.5]
    z = [3.0, 1.0, 2.0, 9.0, 5.0, np.inf, 5.0]
    pitch = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, np.nan]
    w = clean_window(t, z, pitch)
    np.testing.assert_array_equal(w.t, [0.1, 0.2, 0.3])
    np.testing.assert_array_equal(w.z, [1.0, 2.0, 3.0])  # the first of a repeated stamp
    assert w.counts.non_finite == 3 and w.counts.duplicates == 1
    assert w.counts.reordered and w.counts.kept == 3
    assert (w.start_s, w.end_s) == (0.1, 0.3)


def test_missing_pitch_is_nan_and_not_a_rejection():
    w = clean_window([0.0, 1.0], [1.0, 2.0])
    assert np.all(np.isnan(w.pitch)) and w.counts.non_finite == 0


@pytest.mark.parametrize(
    ('t', 'z', 'pitch', 'match'),
    [
        ([0.0, 1.0], [1.0], None, '2 stamps, 1 z'),
        ([[0.0, 1.0]], [[1.0, 2.0]], None, '1-D'),
        (['a', 'b'], [1.0, 2.0], None, 'expected numbers'),
        ([0.0, 1.0], [1.0, 2.0], [0.0], 'pitch values'),
    ],
)
def test_clean_window_rejects_malformed_input(t, z, pitch, match):
    with pytest.raises(LumpbeamError, match=match):
        clean_window(t, z, pitch)


def test_clean_loads_keeps_last_reading_per_stamp():
    loads = clean_loads([1.0, 0.0, 1.0, np.nan], [0.0, 4.5, 2.0, 1.0])
    np.testing.assert_array_equal(loads.t, [0.0, 1.0])
    np.testing.assert_array_equal(loads.kg, [4.5, 2.0])
    with pytest.raises(LumpbeamError, match='2 stamps but 1 masses'):
        clean_loads([0.0, 1.0], [1.0])


def test_x_travels_with_its_pose_and_is_nan_when_not_given():
    window = clean_window(
        [2.0, 1.0, 1.0, np.nan], [-2.0, -1.0, -9.0, 0.0], None, x=[20, 10, 90, 0]
    )
    np.testing.assert_array_equal(window.poses.x, [10.0, 20.0])
    np.testing.assert_array_equal(window.t, window.poses.t)
    assert window.poses.frame_id == 'beam_base' and len(window) == 2
    assert np.isnan(clean_window([1.0], [0.0]).poses.x).all()
    with pytest.raises(LumpbeamError, match='2 stamps but 1 x values'):
        clean_window([1.0, 2.0], [0.0, 0.0], x=[0.0])
