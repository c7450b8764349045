"""ParamsAges: which /beam_params messages time the chain, and their ages."""

import math

import numpy as np
import pytest

from lumpbeam_lab.bench.camera_stream import BEFORE_RELEASE_S, ParamsAges, drop_test_frames


def _ages(messages):
    ages = ParamsAges()
    for published_s, window_end_s in messages:
        ages.add(round(published_s * 1e9), window_end_s)
    return ages


def test_each_newer_frame_is_timed_from_its_stamp():
    ages = _ages([(1.010, 1.000), (1.112, 1.100), (1.215, 1.200)])
    assert ages.latencies_ms == pytest.approx([10.0, 12.0, 15.0])
    assert ages.repeated == 0


def test_a_window_repeated_while_no_pose_comes_is_counted_not_timed():
    # The stream ended at 2.0 s; the timer goes on publishing the same window at 10 Hz.
    ages = _ages([(2.010, 2.000), (2.110, 2.000), (2.210, 2.000), (2.310, 1.995)])
    assert ages.latencies_ms == pytest.approx([10.0])
    assert ages.repeated == 3


@pytest.mark.parametrize('window_end_s', [math.nan, math.inf, -math.inf])
def test_a_message_without_a_window_is_ignored(window_end_s):
    ages = _ages([(1.0, window_end_s), (1.2, 1.19)])
    assert ages.latencies_ms == pytest.approx([10.0])
    assert ages.repeated == 0


def test_the_stream_is_the_drop_test_from_before_the_release():
    frames = drop_test_frames(160, 120, 180.0, 1.5)
    assert frames.shape == (270, 120, 160) and frames.dtype == np.uint8
    # At rest for the second before the release (a noise-free render: identical frames),
    # then moving.
    still = round(BEFORE_RELEASE_S * 180.0)
    assert np.array_equal(frames[0], frames[still - 1])
    assert not np.array_equal(frames[still - 1], frames[still + 20])


def test_the_message_that_brings_the_streams_last_frame_is_counted_not_timed():
    # Frames end at 3.000 s; the 10 Hz timer's next tick publishes that window 80 ms later:
    # the age of a window nothing newer could follow, not the chain's latency.
    ages = _ages([(2.910, 2.900), (3.080, 3.000), (3.180, 3.000)])
    ages.end_of_stream(3.000)
    assert ages.latencies_ms == pytest.approx([10.0])
    assert ages.repeated == 2
