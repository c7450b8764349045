"""The gap between a model and a measurement, on decays whose figures are known exactly."""

import math

import numpy as np
import pytest

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.diagnose.gap import SETTLE_S, decay_mode, measure_gap
from lumpbeam_ros.core.diagnose.measurement import record_from_trajectory
from lumpbeam_ros.core.model.trajectory import TipTrajectory

RATE_HZ = 180.0
EVENT_S = 1.0


def _decay(
    f_n: float, zeta: float, amplitude: float = 2e-3, level: float = -0.02
) -> TipTrajectory:
    """A one-mode ring-down after a release at EVENT_S, level before it."""
    t = np.arange(0.0, 8.0, 1.0 / RATE_HZ)
    omega_n = 2 * math.pi * f_n
    sigma, omega_d = zeta * omega_n, omega_n * math.sqrt(1 - zeta**2)
    tau = np.clip(t - EVENT_S, 0.0, None)
    z = level + np.where(
        t >= EVENT_S, amplitude * np.exp(-sigma * tau) * np.cos(omega_d * tau), amplitude
    )
    zeros = np.zeros_like(t)
    return TipTrajectory(t, zeros + 2.3, z, zeros, zeros)


@pytest.mark.parametrize(('f_n', 'zeta'), [(3.0588, 0.00237), (1.5, 0.02), (6.0, 0.05)])
def test_decay_mode_recovers_the_frequency_and_damping(f_n, zeta):
    trajectory = _decay(f_n, zeta)
    mode = decay_mode(trajectory.t, trajectory.z, EVENT_S)
    assert mode.natural_frequency_hz == pytest.approx(f_n, rel=1e-6)
    assert mode.damping_ratio == pytest.approx(zeta, rel=1e-4)


def test_the_gap_of_a_model_against_itself_is_zero():
    measured = _decay(3.0588, 0.00237)
    record = record_from_trajectory(measured, [(EVENT_S, 0.0)], 4.5)
    mode = decay_mode(measured.t, measured.z, EVENT_S)
    gap = measure_gap(record, measured, mode)
    assert gap.rms_m == 0.0 and gap.max_m == 0.0
    assert gap.frequency_error == pytest.approx(0.0, abs=1e-9)
    assert gap.damping_error == pytest.approx(0.0, abs=1e-6)


def test_a_model_off_in_frequency_and_damping_shows_both_errors():
    measured = _decay(3.0, 0.01)
    model = _decay(3.0 * 1.02, 0.01 * 0.8)
    record = record_from_trajectory(measured, [(EVENT_S, 0.0)], 4.5)
    gap = measure_gap(record, model, decay_mode(measured.t, measured.z, EVENT_S))
    assert gap.frequency_error == pytest.approx(0.02, rel=1e-4)
    assert gap.damping_error == pytest.approx(-0.2, rel=1e-3)
    residual = model.z - measured.z
    assert gap.rms_m == pytest.approx(float(np.sqrt(np.mean(residual**2))))
    assert gap.max_m == pytest.approx(float(np.max(np.abs(residual))))
    assert set(gap.as_dict()) == {'rms_m', 'max_m', 'frequency_error', 'damping_error'}


def test_too_short_a_decay_is_refused():
    trajectory = _decay(3.0, 0.01)
    end = trajectory.t[-1]
    with pytest.raises(LumpbeamError):
        decay_mode(trajectory.t, trajectory.z, end - SETTLE_S - 0.01)
