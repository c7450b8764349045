import math

import numpy as np
import pytest

from lumpbeam_ros.core.bagio.tipbuffer import TipBuffer
from lumpbeam_ros.core.bagio.tipseries import SampleCounts


@pytest.mark.parametrize(
    ('stamp', 'z', 'pitch', 'kind'),
    [
        (2.0, math.nan, 0.0, 'non_finite'),
        (2.0, 0.0, math.inf, 'non_finite'),
        (math.nan, 0.0, 0.0, 'non_finite'),
        (1.0, 0.0, 0.0, 'duplicates'),
        (0.5, 0.0, 0.0, 'out_of_order'),
    ],
)
def test_every_dropped_pose_is_counted_by_its_kind(stamp, z, pitch, kind):
    buffer = TipBuffer(keep_s=10.0, max_rate_hz=10.0, reset_jump_back_s=1.0)
    assert buffer.push(1.0, 0.0, 0.0)
    assert not buffer.push(stamp, z, pitch)
    counts = buffer.counts
    assert getattr(counts, kind) == 1 and counts.dropped == 1 and counts.received == 2
    assert len(buffer) == 1


def test_a_jump_back_the_next_pose_confirms_empties_the_buffer_and_is_counted():
    buffer = TipBuffer(keep_s=10.0, max_rate_hz=10.0, reset_jump_back_s=1.0)
    for stamp in (5.0, 6.0, 7.0):
        buffer.push(stamp, 1.0)
    assert not buffer.push(5.5, 2.0)  # 1.5 s back: a loop or a corrupt stamp, held
    assert buffer.holding and len(buffer) == 3 and buffer.counts.resets == 0
    assert buffer.push(5.6, 3.0)  # nearer the held pose: the clock went back
    assert buffer.counts.resets == 1 and len(buffer) == 2 and buffer.newest_s == 5.6
    poses, counts = buffer.latest()
    assert poses.z.tolist() == [2.0, 3.0] and counts == SampleCounts(received=2)


@pytest.mark.parametrize('outlier', [7.0 + 163.0, 7.0 - 1000.0, 1e18])
def test_one_stamp_far_off_the_time_line_is_dropped_and_blinds_nothing(outlier):
    buffer = TipBuffer(keep_s=10.0, max_rate_hz=10.0, reset_jump_back_s=1.0)
    for stamp in (5.0, 6.0, 7.0):
        buffer.push(stamp, 1.0)
    assert not buffer.push(outlier, 9.0)
    assert buffer.push(7.1, 1.0)  # nearer the time line: the held stamp was an outlier
    assert buffer.push(7.2, 1.0)
    assert not buffer.holding and buffer.counts.resets == 0
    assert buffer.t.tolist() == [5.0, 6.0, 7.0, 7.1, 7.2] and 9.0 not in buffer.z
    assert buffer.counts.out_of_order == 1


def test_a_stream_that_pauses_resumes_after_its_first_pose():
    buffer = TipBuffer(keep_s=100.0, max_rate_hz=10.0, reset_jump_back_s=1.0)
    for stamp in (0.0, 0.1, 5.0, 5.1, 10.0, 15.0):  # a pause, then two slow poses
        buffer.push(stamp, 1.0)
    assert buffer.t.tolist() == [0.0, 0.1, 5.0, 5.1, 10.0] and buffer.holding
    assert buffer.counts.dropped == 0


def test_a_stretch_counts_what_was_dropped_while_its_poses_arrived():
    buffer = TipBuffer(keep_s=100.0, max_rate_hz=10.0, reset_jump_back_s=5.0)
    for k in range(10):
        buffer.push(float(k), 0.0)
        if k >= 5:
            buffer.push(float(k) - 0.5, 0.0)  # a second, late stream from the 5th pose on
            buffer.push(float(k), math.nan)
    _, early = buffer.between(0.0, 4.0)
    _, late = buffer.between(5.0, 9.0)
    assert early == SampleCounts(received=5)
    assert late == SampleCounts(received=15, non_finite=5, duplicates=5)
    assert late.untrusted and not early.untrusted
    _, whole = buffer.latest()
    assert (whole.received, whole.kept, whole.dropped) == (20, 10, 10)


def test_the_ring_keeps_the_newest_keep_s_in_order_and_wraps():
    buffer = TipBuffer(keep_s=1.0, max_rate_hz=10.0, reset_jump_back_s=1.0)
    t = np.arange(0.0, 5.0, 0.1)
    for stamp in t:
        buffer.push(stamp, 2.0 * stamp, -stamp, x=stamp)
    poses, counts = buffer.latest()
    expected = t[t >= t[-1] - 1.0 - 1e-12]
    np.testing.assert_allclose(poses.t, expected)
    np.testing.assert_allclose(poses.z, 2.0 * expected)
    np.testing.assert_allclose(poses.x, expected)
    assert counts.dropped == 0 and buffer.oldest_s == pytest.approx(expected[0])


def test_an_empty_buffer_gives_no_poses_and_the_drops_since_it_was_emptied():
    buffer = TipBuffer(keep_s=1.0, max_rate_hz=10.0, reset_jump_back_s=1.0)
    buffer.push(1.0, math.nan)
    poses, counts = buffer.latest()
    assert len(poses) == 0 and counts == SampleCounts(received=1, non_finite=1)
    buffer.clear()
    assert buffer.latest()[1] == SampleCounts() and buffer.counts.non_finite == 1


@pytest.mark.parametrize(
    ('keep_s', 'rate', 'jump'),
    [(0.0, 1.0, 1.0), (1.0, -1.0, 1.0), (1.0, 1.0, 0.0), (1e308, 1e308, 1.0)],
)
def test_bad_sizes_are_refused(keep_s, rate, jump):
    with pytest.raises(ValueError):
        TipBuffer(keep_s, rate, jump)
