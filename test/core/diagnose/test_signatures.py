import numpy as np
import pytest

from lumpbeam_ros.core.diagnose.measurement import make_record
from lumpbeam_ros.core.diagnose.signatures import (
    decay_peaks,
    envelope_law,
    envelope_rates,
    envelope_terms,
    time_shift,
)
from lumpbeam_ros.core.model.trajectory import TipTrajectory

T = np.arange(0.0, 12.0, 1.0 / 180.0)
TAU = np.clip(T - 2.0, 0.0, None)


@pytest.mark.parametrize(
    ('envelope', 'law'),
    [
        (0.02 * np.exp(-0.15 * TAU), 'exponential'),
        (np.clip(0.02 - 0.0018 * TAU, 0.0, None), 'linear'),
        (0.02 / (1.0 + 0.3 * TAU), 'amplitude_dependent'),
        # Viscous plus a little dry friction: dA/dt = -0.05 A - 2e-4.
        ((0.02 + 0.004) * np.exp(-0.05 * TAU) - 0.004, 'linear'),
    ],
)
def test_the_envelope_law_of_a_decay_is_recognised(envelope, law):
    z = (
        -0.03
        + envelope * np.cos(19.2 * TAU)
        + 1e-6 * np.random.default_rng(0).standard_normal(T.size)
    )
    peak_t, peak_a = decay_peaks(T, z, 2.0, -0.03)
    assert 40 < peak_t.size < 70  # two peaks per 3 Hz period
    assert envelope_law(envelope_terms(peak_t, peak_a)) == law


def test_too_few_peaks_give_no_terms_and_the_plain_law():
    terms = envelope_terms(np.arange(5.0), np.ones(5))
    assert all(np.isnan(v) for v in terms.values())
    assert envelope_law(terms) == 'exponential'


@pytest.mark.parametrize('delay', [0.0, 0.015, 0.04])
def test_time_shift_finds_a_late_measurement(delay):
    def z_of(t):
        tau = np.clip(t - 2.0, 0.0, None)
        return -0.07 + 0.04 * (1.0 - np.exp(-0.1 * tau) * np.cos(19.2 * tau))

    model = TipTrajectory(T, T * 0, z_of(T), T * 0, T * 0)
    record = make_record(T, z_of(T - delay), T * 0, 4.5, [(2.0, 0.0)])
    assert time_shift(record, model) == pytest.approx(delay, abs=6e-4)


@pytest.mark.parametrize(('viscous', 'dry'), [(0.05, 2e-4), (0.12, 0.0), (0.0, 1.5e-3)])
def test_envelope_rates_separate_the_viscous_and_the_dry_loss(viscous, dry):
    # Peaks half a 3 Hz period apart on dA/dt = -a A - b, solved exactly.
    t = np.arange(0.0, 8.0, 1.0 / 6.0)
    if viscous > 0.0:
        amplitude = (0.02 + dry / viscous) * np.exp(-viscous * t) - dry / viscous
    else:
        amplitude = 0.02 - dry * t
    a, b = envelope_rates(t, amplitude)
    assert a == pytest.approx(viscous, abs=2e-4)
    assert b == pytest.approx(dry, abs=2e-6)
    assert all(np.isnan(envelope_rates(t[:7], amplitude[:7])))
