import math

import numpy as np
import pytest
from ring_downs import MOVE_S, ring_down

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.ring_down import (
    SOURCE,
    RestTracker,
    along_swing,
    last_ring_down,
    rest_stretches,
    ring_down_release,
)
from lumpbeam_ros.core.ident.samples import clean_window


def _two_moves():
    t = np.arange(0, 4.0, 1 / 180)
    q = np.zeros((t.size, 2))
    q[(t > 1.0) & (t < 1.5), 0] = np.linspace(0, 0.2, np.count_nonzero((t > 1.0) & (t < 1.5)))
    q[t >= 1.5, 0] = 0.2
    q[(t > 2.5) & (t < 2.8), 1] = 0.1
    q[t >= 2.8, 1] = -0.3
    return t, q


def test_the_whole_record_and_the_live_tracker_apply_one_rule():
    t, q = _two_moves()
    stretches = rest_stretches(t, q, 1e-5)
    tracker = RestTracker(1e-5)
    seen = []
    for stamp, row in zip(t, q, strict=True):
        tracker.push(float(stamp), row)
        if tracker.previous is not None and (not seen or seen[-1] is not tracker.previous):
            seen.append(tracker.previous)
    assert [*seen, tracker.current] == stretches
    last = last_ring_down(stretches, 0.5)
    assert last.start_s == pytest.approx(t[t >= 2.8][0]) and last.angles_rad == (0.2, -0.3)
    assert not last.moved_again and tracker.ring_down(0.5) == last
    # The rest between the moves is a ring-down too, ended by the next move.
    between = [s for s in stretches if s.after_move and s.duration_s > 0.5][0]
    assert between.moved_again and ring_down_release(between).decay_end_s == between.end_s


def test_a_minimum_jerk_stop_is_found_within_a_few_frames():
    record = ring_down()
    rest = last_ring_down(rest_stretches(record.t, record.q, 1e-5), 0.3)
    assert MOVE_S - 3 / 180 <= rest.start_s <= MOVE_S + 1e-9
    release = ring_down_release(rest)
    assert release.source == SOURCE and release.found and release.load_kg == 0.0
    assert math.isinf(release.decay_end_s)


def test_no_move_or_no_rest_is_one_line():
    t = np.arange(0, 2, 1 / 180)
    with pytest.raises(LumpbeamError, match='never move'):
        last_ring_down(rest_stretches(t, np.zeros((t.size, 1)), 1e-5), 0.3)
    with pytest.raises(LumpbeamError, match='rest at most'):
        last_ring_down(rest_stretches(t, t[:, None], 1e-5), 0.3)


def test_the_tracker_ignores_bad_samples():
    tracker = RestTracker(1e-3)
    assert tracker.push(1.0, np.array([0.0, 0.1]))
    assert not tracker.push(1.1, np.array([np.nan, 0.1]))
    assert not tracker.push(0.5, np.array([0.0, 0.1]))
    assert not tracker.push(1.2, np.array([0.0]))
    assert tracker.push(1.3, np.array([0.0, 0.1])) and tracker.current.end_s == 1.3
    with pytest.raises(ValueError):
        RestTracker(0.0)


def test_the_swing_is_taken_across_the_link():
    record = ring_down(end_rad=0.5)
    window = clean_window(record.t, record.z, None, x=record.x)
    swing = along_swing(window, MOVE_S, float(record.t[-1]))
    after = record.t > MOVE_S
    # The link points at -0.5 rad: across it is (sin q, cos q); the swing keeps its sign. The
    # direction comes from the noisy data, so it is right to a few 1e-4 rad: 1 um of 5 mm.
    expected = np.sin(0.5) * record.x + np.cos(0.5) * record.z
    gap = swing.z[after] - expected[after]
    assert np.max(np.abs(gap - gap.mean())) < 2e-6
    # Without a measured x, z is kept.
    plain = clean_window(record.t, record.z)
    assert along_swing(plain, MOVE_S, 6.0) is plain


def test_the_rest_needed_is_min_samples_pose_periods():
    from lumpbeam_ros.core.ident.ring_down import min_rest_s
    from lumpbeam_ros.core.ident.samples import clean_window

    t = np.arange(0.0, 1.0, 0.01)
    window = clean_window(t, np.zeros_like(t), np.zeros_like(t))
    assert min_rest_s(window, 50) == pytest.approx(0.5)
    assert min_rest_s(clean_window(t[:1], t[:1], t[:1]), 50) == 0.0
