"""A footage frame: its stamp in seconds, the defaults, an undecodable frame."""

import dataclasses
from fractions import Fraction

import numpy as np
import pytest

from lumpbeam_ros.core.vision.sources.frame import FootageFrame


@pytest.mark.parametrize(
    ('stamp_ns', 'seconds'),
    [
        (0, 0.0),
        (1, 1e-9),
        (5_555_555_556, 5.555555556),
        (1_700_000_000_123_456_789, 1_700_000_000.123456789),
        (-2_000_000_000, -2.0),
    ],
    ids=['zero', 'one-ns', 'at-180-hz', 'epoch', 'before-zero'],
)
def test_the_stamp_in_seconds(stamp_ns, seconds):
    frame = FootageFrame(3, stamp_ns, 'clip.avi frame 3', np.zeros((2, 2), np.uint8))
    # The float nearest the exact quotient: no rounding on the way (an epoch stamp in float
    # seconds resolves ~0.24 us, so the tracker's seconds are as good as a float gets).
    assert frame.stamp == float(Fraction(stamp_ns, 10**9))
    assert frame.stamp == pytest.approx(seconds, rel=1e-15, abs=1e-18)
    assert frame.stamp_ns == stamp_ns  # the exact stamp is kept beside the float


def test_a_frame_is_mono8_without_a_problem_by_default():
    frame = FootageFrame(0, 0, 'a.png', np.zeros((2, 3), np.uint8))
    assert (frame.encoding, frame.problem) == ('mono8', '')


def test_an_undecodable_frame_carries_why():
    frame = FootageFrame(7, 10, 'b.png', None, problem='truncated PNG')
    assert frame.pixels is None and frame.problem == 'truncated PNG'


def test_a_frame_cannot_be_changed():
    frame = FootageFrame(0, 0, 'a.png', None)
    with pytest.raises(dataclasses.FrozenInstanceError):
        frame.stamp_ns = 5
