import math

import numpy as np
import pytest

from lumpbeam_ros.ident.config import IdentifierConfig
from lumpbeam_ros.ident.release import detect_release
from lumpbeam_ros.ident.samples import clean_loads, clean_window

CONFIG = IdentifierConfig()


def _window(trajectory, loads=None):
    return clean_window(trajectory.t, trajectory.z, trajectory.pitch, loads)


def test_release_from_the_data(drop_case):
    trajectory, truth = drop_case()
    release = detect_release(_window(trajectory), CONFIG)
    assert release.source == 'data' and release.confidence == 1.0
    assert abs(release.time_s - truth.release_time_s) < 1.0 / 180.0
    assert release.level_before_m == pytest.approx(truth.level_before_m, abs=5e-6)
    assert release.level_before_std_m == pytest.approx(20e-6 / math.sqrt(360), rel=0.3)
    assert release.step_snr > 1000 and math.isnan(release.load_kg)


def test_release_from_tip_load(drop_case):
    trajectory, truth = drop_case()
    loads = clean_loads([0.0, 1.0, 2.0, 3.0], [4.5, 4.5, 0.0, 0.0])
    release = detect_release(_window(trajectory, loads), CONFIG)
    assert release.source == 'tip_load' and release.time_s == 2.0
    assert (release.load_kg, release.load_after_kg) == (4.5, 0.0)


def test_tip_load_drop_the_tip_ignores_is_low_confidence(drop_case):
    trajectory, _ = drop_case()
    loads = clean_loads([0.0, 1.0], [4.5, 0.0])
    quiet = trajectory.slice_time(0.0, 1.9)
    release = detect_release(_window(quiet, loads), CONFIG)
    assert release.source == 'tip_load' and release.confidence < CONFIG.min_release_confidence
    assert 'rose only' in release.message


@pytest.mark.parametrize(
    ('start', 'end', 'message'),
    [
        (0.0, 1.9, 'no step'),  # static only
        (3.0, 12.0, 'quiet'),  # starts mid-oscillation
        (1.9, 4.0, 'quiet static level'),  # release after too short a quiet stretch
    ],
)
def test_no_release_found(drop_case, start, end, message):
    trajectory, _ = drop_case()
    release = detect_release(_window(trajectory.slice_time(start, end)), CONFIG)
    assert not release.found and release.source == 'none'
    assert message in release.message


def test_falling_level_is_not_a_release(drop_case):
    trajectory, _ = drop_case()
    flipped = clean_window(trajectory.t, -0.1 - trajectory.z, trajectory.pitch)
    release = detect_release(flipped, CONFIG)
    assert not release.found and 'added' in release.message


def test_small_step_is_rejected():
    rng = np.random.default_rng(0)
    t = np.arange(0, 4, 1 / 180)
    z = np.where(t < 2, 0.0, 1e-4) + rng.normal(0, 20e-6, t.size)
    release = detect_release(clean_window(t, z), CONFIG)
    assert not release.found and 'noise sigmas' in release.message
