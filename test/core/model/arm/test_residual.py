"""The residual vibration after a move: a known ring-down, the window, the rest, bad input."""

import math

import numpy as np
import pytest
from arm_cases import small_arm, smooth_move

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.residual import WINDOW_S, arm_residual, residual_rms, rest_tip
from lumpbeam_ros.core.model.arm.simulate import simulate_arm
from lumpbeam_ros.core.model.arm.statics import arm_equilibrium


@pytest.mark.parametrize('amplitude', [1e-3, 0.02])
def test_an_undamped_sine_about_the_rest_has_rms_amplitude_over_root_two(amplitude):
    t = np.arange(0.0, 5.0, 1e-3)
    rest = (0.7, -0.2)
    # Ringing along a slanted line: the distance is |a sin|, whatever the direction.
    swing = amplitude * np.sin(2 * math.pi * 4.0 * t)
    x = rest[0] + 0.6 * swing
    z = rest[1] + 0.8 * swing
    got = residual_rms(t, x, z, rest, move_end_s=1.0)
    assert got == pytest.approx(amplitude / math.sqrt(2), rel=1e-3)


def test_only_the_window_after_the_move_counts():
    t = np.arange(0.0, 6.0, 1e-3)
    x = np.where(t < 1.0, 5.0, 0.0) + np.where(t > 1.0 + WINDOW_S + 0.01, 7.0, 0.0)
    z = np.zeros_like(t)
    # Before the move's end and after the window the tip is far off: neither counts.
    assert residual_rms(t, x, z, (0.0, 0.0), move_end_s=1.0 + 1e-3) == 0.0
    assert residual_rms(t, x, z, (0.0, 0.0), 1.0 + 1e-3, window_s=1.0) == 0.0


def test_a_damped_ring_down_matches_its_closed_form():
    zeta, f, a = 0.02, 4.0, 0.01
    omega = 2 * math.pi * f
    t = np.arange(0.0, 4.0, 1e-4)
    x = a * np.exp(-zeta * omega * t) * np.cos(omega * t)
    got = residual_rms(t, x, np.zeros_like(t), (0.0, 0.0), move_end_s=0.0)
    # Mean of a^2 e^{-2 zeta omega t} cos^2 over [0, 3]: half the exponential's mean.
    expected = math.sqrt(a**2 * (1 - math.exp(-2 * zeta * omega * 3.0)) / (4 * zeta * omega * 3.0))
    assert got == pytest.approx(expected, rel=2e-3)


def test_the_rest_is_the_static_equilibrium_at_the_final_angles():
    model = ArmModel.from_config(small_arm(2))
    q = np.array([0.4, -0.7])
    x, z, _ = model.chain.tip_pose(arm_equilibrium(model, q))
    assert rest_tip(model, q) == pytest.approx((float(x), float(z)), abs=0.0)


def test_a_simulated_move_rings_and_its_residual_decays_with_the_window_start():
    model = ArmModel.from_config(small_arm(1))
    move = smooth_move(np.array([0.8]), 0.4)
    t = np.arange(0.0, 4.5, 2e-3)
    motion = simulate_arm(model, move, t)
    early = arm_residual(model, motion, move_end_s=0.4)
    late = arm_residual(model, motion, move_end_s=1.4)
    assert early > 1e-4  # the move leaves the link ringing
    assert late < early  # the damped ringing dies down


@pytest.mark.parametrize(
    ('t', 'x', 'end', 'window', 'message'),
    [
        (np.arange(0.0, 2.0, 1e-3), None, 0.0, WINDOW_S, 'do not cover'),
        (np.arange(0.0, 5.0, 1e-3), None, -1.0, WINDOW_S, 'do not cover'),
        (np.arange(0.0, 5.0, 1e-3), None, 0.5, 0.0, 'window must be positive'),
        (np.arange(0.0, 5.0, 1e-3), None, 0.5, math.nan, 'window must be positive'),
        (np.arange(0.0, 5.0, 1e-3), np.zeros(3), 0.5, WINDOW_S, 'times for'),
    ],
)
def test_bad_input_is_one_clear_error(t, x, end, window, message):
    x = np.zeros_like(t) if x is None else x
    with pytest.raises(LumpbeamError, match=message):
        residual_rms(t, x, np.zeros_like(t), (0.0, 0.0), end, window)
