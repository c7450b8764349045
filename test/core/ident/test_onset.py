import math

import numpy as np
import pytest

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.onset import PEAK_FRACTION, fit_onset
from lumpbeam_ros.core.model.parameters import DropTestConfig

from .conftest import make_drop_case

RATE_HZ = 180.0
FRAME_S = 1.0 / RATE_HZ
EPOCH_S = 1_700_000_000.0  # stamps as a live recording has them

# Off the fit's grid of a twentieth of a frame, so that only the refinement reaches them.
FRACTIONS = [0.13, 0.37, 0.62, 0.93]


def _onset_model(fraction, t0=0.0, z0=-0.05, coef=(3.0, -20.0, 40.0), n=120, departure=40):
    """Samples of the model itself: z0, then z0 + c2 tau^2 + c3 tau^3 + c4 tau^4.

    The release lies ``fraction`` of a frame after sample ``departure - 1``. The stamps carry
    ``t0``; the positions are computed from the exact times.
    """
    t_rel = np.arange(n) * FRAME_S
    release = (departure - 1 + fraction) * FRAME_S
    tau = np.clip(t_rel - release, 0.0, None)
    z = z0 + sum(c * tau**p for c, p in zip(coef, (2, 3, 4), strict=True))
    return t0 + t_rel, z, t0 + release, departure


@pytest.mark.parametrize('t0', [0.0, EPOCH_S], ids=['from 0', 'epoch'])
@pytest.mark.parametrize('fraction', FRACTIONS)
def test_the_onset_of_the_model_itself_is_found_to_a_thousandth_of_a_frame(fraction, t0):
    t, z, release, departure = _onset_model(fraction, t0)
    onset = fit_onset(t, z, departure, 5, 99)
    assert abs(onset.time_s - release) < 1e-3 * FRAME_S
    assert onset.level_m == pytest.approx(-0.05, abs=1e-9)
    # From the quiet start to 0.6 of the way from the departure to the peak.
    assert onset.samples == departure + math.floor(PEAK_FRACTION * (99 - departure)) + 1 - 5
    assert onset.time_std_s < 1e-3 * FRAME_S  # no noise: only the stamps' rounding


def _departure_and_peak(t, z, release_s):
    """The indices the release detector hands the fit.

    The first sample 5 sigma off the static level, and the first peak of the rise after it.
    """
    quiet = t < release_s - 0.1
    level, sigma = np.median(z[quiet]), np.std(z[quiet])
    departure = int(np.flatnonzero((np.abs(z - level) > 5.0 * sigma) & ~quiet)[0])
    half_period = int(RATE_HZ / 2.0 / 3.0)  # the first mode is near 3 Hz
    return departure, departure + int(np.argmax(z[departure : departure + half_period]))


@pytest.fixture(scope='module')
def released():
    """Noisy drops of the nonlinear lumped beam (20 um), released 0.37 frame after a sample."""
    release_s = 2.0 + 0.37 * FRAME_S
    drop = DropTestConfig(release_time_s=release_s)
    return release_s, [make_drop_case(drop=drop, seed=seed) for seed in range(24)]


@pytest.mark.parametrize('t0', [0.0, EPOCH_S], ids=['from 0', 'epoch'])
def test_a_simulated_release_is_timed_within_its_uncertainty(released, t0):
    release_s, cases = released
    errors, stds = [], []
    for trajectory, truth in cases:
        t, z = trajectory.t, trajectory.z
        departure, peak = _departure_and_peak(t, z, release_s)
        onset = fit_onset(t + t0, z, departure, departure - 90, peak)
        errors.append(onset.time_s - t0 - release_s)
        stds.append(onset.time_std_s)
        assert onset.level_m == pytest.approx(truth.level_before_m, abs=10e-6)
    errors, stds = np.array(errors), np.array(stds)
    assert np.max(np.abs(errors)) < 0.1 * FRAME_S  # the module's claim: hundredths of a frame
    assert abs(np.mean(errors)) < 3.0 * np.std(errors) / math.sqrt(errors.size) + 0.01 * FRAME_S
    # The covariance's std agrees with the spread over noise draws.
    assert 0.5 < np.std(errors) / np.mean(stds) < 2.0


def test_stamps_with_an_epoch_offset_give_the_same_onset(released):
    release_s, cases = released
    trajectory, _ = cases[0]
    departure, peak = _departure_and_peak(trajectory.t, trajectory.z, release_s)
    near = fit_onset(trajectory.t, trajectory.z, departure, departure - 90, peak)
    far = fit_onset(trajectory.t + EPOCH_S, trajectory.z, departure, departure - 90, peak)
    # The stamps themselves are rounded to 2.4e-7 s at 1.7e9 s.
    assert far.time_s - EPOCH_S == pytest.approx(near.time_s, abs=1e-6)
    assert far.time_std_s == pytest.approx(near.time_std_s, rel=0.05)
    assert far.level_m == pytest.approx(near.level_m, abs=1e-8)


@pytest.mark.parametrize(
    ('departure', 'quiet_start', 'peak'),
    [
        (40, 40, 100),  # no quiet stretch
        (40, 50, 100),  # quiet start after the departure
        (40, -1, 100),
        (100, 5, 40),  # peak before the departure
        (40, 5, 40),
        (40, 5, 120),  # peak past the end
    ],
)
def test_indices_out_of_order_are_refused(departure, quiet_start, peak):
    t, z, _, _ = _onset_model(0.37)
    with pytest.raises(LumpbeamError, match='no quiet stretch and rise around the release'):
        fit_onset(t, z, departure, quiet_start, peak)


def test_too_short_a_stretch_is_refused():
    t, z, _, _ = _onset_model(0.37, n=12, departure=8)
    with pytest.raises(LumpbeamError, match='too few samples between the release and the first'):
        fit_onset(t, z, 8, 6, 10)
