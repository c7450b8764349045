import numpy as np
import pytest

from lumpbeam_ros.core.ident.samples import clean_loads, clean_window
from lumpbeam_ros.core.ident.segments import keep_release_segment
from lumpbeam_ros.core.ident.settings import IdentifierConfig

CONFIG = IdentifierConfig()


def test_no_gap_keeps_the_window(drop_case):
    trajectory, _ = drop_case()
    window = clean_window(trajectory.t, trajectory.z, trajectory.pitch)
    kept, note = keep_release_segment(window, CONFIG)
    assert kept is window and note == ''


@pytest.mark.parametrize('jump_s', [100.0, 1e6])
def test_the_stretch_with_the_release_is_kept(drop_case, jump_s):
    trajectory, _ = drop_case()
    t = trajectory.t.copy()
    t[t > 8.0] += jump_s
    loads = clean_loads([0.0, 2.0], [4.5, 0.0])
    window = clean_window(t, trajectory.z, trajectory.pitch, loads)
    kept, note = keep_release_segment(window, CONFIG)
    assert kept.start_s == 0.0 and kept.end_s == pytest.approx(8.0, abs=0.01)
    assert kept.loads.t.tolist() == [0.0, 2.0]
    assert 'stamps jump by' in note and 'the release)' in note


def test_without_a_release_the_longest_stretch_is_kept():
    t = np.concatenate([np.arange(0, 1, 0.01), np.arange(100, 103, 0.01)])
    window = clean_window(t, np.zeros(t.size))
    kept, note = keep_release_segment(window, CONFIG)
    assert kept.start_s == 100.0 and len(kept) == 300
    assert 'the most poses' in note and 'dropped 100 poses in 1 other stretch' in note
