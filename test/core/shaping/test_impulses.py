"""Modes refuse what is not an underdamped mode; impulse sequences convolve exactly."""

import math

import numpy as np
import pytest

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.shaping.impulses import Impulses, Mode


@pytest.mark.parametrize(
    ('frequency_hz', 'damping_ratio', 'problem'),
    [
        (0.0, 0.01, 'natural frequency must be a positive number of Hz, got 0.0'),
        (-2.0, 0.01, 'natural frequency must be a positive number of Hz, got -2.0'),
        (math.nan, 0.01, 'natural frequency must be a positive number of Hz, got nan'),
        (math.inf, 0.01, 'natural frequency must be a positive number of Hz, got inf'),
        (3.0, -0.01, 'damping ratio must be in [0, 1) (an underdamped mode), got -0.01'),
        (3.0, 1.0, 'damping ratio must be in [0, 1) (an underdamped mode), got 1.0'),
        (3.0, math.nan, 'damping ratio must be in [0, 1) (an underdamped mode), got nan'),
    ],
)
def test_bad_modes_are_one_line(frequency_hz, damping_ratio, problem):
    with pytest.raises(LumpbeamError, match=None) as caught:
        Mode(frequency_hz, damping_ratio)
    assert str(caught.value) == problem


def test_damped_period():
    assert Mode(2.0, 0.0).damped_period_s == 0.5
    assert Mode(2.0, 0.6).damped_period_s == pytest.approx(0.5 / 0.8, rel=1e-15)


def test_convolution_sums_times_multiplies_amplitudes_and_merges_coincident_impulses():
    a = Impulses([0.0, 0.5], [0.25, 0.75])
    b = Impulses([0.0, 0.5, 1.0], [0.5, 0.25, 0.25])
    c = a.convolve(b)
    assert c.time_s.tolist() == [0.0, 0.5, 1.0, 1.5]
    expected = [0.125, 0.0625 + 0.375, 0.0625 + 0.1875, 0.1875]
    assert c.amplitude.tolist() == pytest.approx(expected, rel=1e-15)
    assert c.duration_s == 1.5
    assert np.sum(c.amplitude) == pytest.approx(1.0, abs=1e-15)
    assert c.as_list()[1] == {'time_s': 0.5, 'amplitude': pytest.approx(0.4375)}


def test_impulse_arrays_are_read_only_and_matched():
    impulses = Impulses([0.0, 0.1], [0.5, 0.5])
    with pytest.raises(ValueError):
        impulses.amplitude[0] = 1.0
    with pytest.raises(ValueError):
        Impulses([0.0, 0.1], [1.0])
