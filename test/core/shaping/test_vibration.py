"""The residual-vibration formula against a simulated mass-spring-damper (scipy.signal.lsim).

The simulation shares nothing with the formula: it integrates the mode driven by the shaped
command (a fast ramp convolved by :func:`shape_trajectory`), fits the free vibration after
the move, and compares its amplitude with that of the unshaped move issued at the time of
the shaper's last impulse (the formula's reference).
"""

import math

import numpy as np
import pytest
from scipy import signal

from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.shaping.apply import shape_trajectory
from lumpbeam_ros.core.shaping.impulses import Impulses, Mode
from lumpbeam_ros.core.shaping.shapers import zvd_shaper
from lumpbeam_ros.core.shaping.vibration import (
    insensitivity_band,
    residual_vibration,
    vibration_summary,
)

#: The commanded move: 1 rad in 20 ms, from rest.
MOVE = JointTrajectory(np.array([0.0, 0.02]), np.array([[0.0], [1.0]]))


def free_vibration_amplitude(command: JointTrajectory, mode: Mode, settle_s: float) -> float:
    """Amplitude (at t = 0) of the decaying sinusoid the mode rings with after the command."""
    omega = 2 * math.pi * mode.frequency_hz
    zeta = mode.damping_ratio
    system = signal.lti([omega**2], [1.0, 2 * zeta * omega, omega**2])
    t = np.arange(0.0, settle_s + 2.0, 2e-4)
    _, x, _ = signal.lsim(system, command.at(t)[:, 0], t)
    after = t > settle_s
    decay = np.exp(-zeta * omega * t[after])
    omega_d = omega * math.sqrt(1 - zeta**2)
    basis = np.column_stack(
        [decay * np.cos(omega_d * t[after]), decay * np.sin(omega_d * t[after])]
    )
    coefficients, *_ = np.linalg.lstsq(basis, x[after] - 1.0, rcond=None)
    return float(np.hypot(*coefficients))


@pytest.mark.parametrize('zeta', [0.0, 0.02, 0.1])
@pytest.mark.parametrize('ratio', [0.7, 0.9, 1.0, 1.15, 1.6])
def test_formula_matches_the_simulated_mode(zeta, ratio):
    design = Mode(3.0, zeta)
    shaper = zvd_shaper(design)
    actual = Mode(3.0 * ratio, zeta)
    shaped = free_vibration_amplitude(shape_trajectory(MOVE, shaper), actual, 0.5)
    late = JointTrajectory(MOVE.time_s + shaper.duration_s, MOVE.angles_rad)
    unshaped = free_vibration_amplitude(late, actual, 0.5)
    formula = float(residual_vibration(shaper, actual.frequency_hz, zeta))
    assert shaped / unshaped == pytest.approx(formula, abs=2e-4)


def test_single_impulse_leaves_all_vibration():
    assert residual_vibration(Impulses([0.0], [1.0]), [1.0, 5.0], 0.05).tolist() == [1.0, 1.0]


def test_band_of_zvd_matches_its_closed_form_without_damping():
    # Undamped ZVD: V = cos^2(pi f / (2 f0)), 0.05 where the cosine is sqrt(0.05).
    mode = Mode(4.0, 0.0)
    low, high = insensitivity_band(zvd_shaper(mode), mode, 0.05)
    edge = 2 / math.pi * math.acos(math.sqrt(0.05))
    assert (low, high) == pytest.approx((4.0 * edge, 4.0 * (2 - edge)), rel=1e-9)


def test_band_is_nan_when_the_design_point_itself_is_not_within_tolerance():
    mode = Mode(4.0, 0.0)
    assert all(math.isnan(x) for x in insensitivity_band(Impulses([0.0], [1.0]), mode, 0.05))


def test_summary_reports_the_design_point_15_percent_off_and_the_band():
    mode = Mode(4.0, 0.0)
    summary = vibration_summary(zvd_shaper(mode), mode)
    assert summary['vibration_left'] < 1e-15
    # Undamped ZVD: V = cos^2(pi f / (2 f0)), symmetric about the design frequency.
    expected = math.cos(math.pi * 0.85 / 2) ** 2
    assert summary['vibration_left_15pct_low'] == pytest.approx(expected, rel=1e-12)
    assert summary['vibration_left_15pct_high'] == pytest.approx(expected, rel=1e-12)
    assert summary['band_hz'] == list(insensitivity_band(zvd_shaper(mode), mode, 0.05))
    assert (summary['natural_frequency_hz'], summary['damping_ratio']) == (4.0, 0.0)
