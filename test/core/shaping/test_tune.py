"""Impulses tuned on the model's simulation: the window's linear map, the tuning's bounds."""

import numpy as np
import pytest
from arm_cases import minimum_jerk, small_arm

from lumpbeam_ros.core.model.arm.drive import SampledMotion
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.residual import rest_tip
from lumpbeam_ros.core.model.arm.simulate import simulate_arm
from lumpbeam_ros.core.shaping.impulses import Impulses, Mode
from lumpbeam_ros.core.shaping.shapers import design_shaper
from lumpbeam_ros.core.shaping.tune import (
    WINDOW_STEP_S,
    RestWindow,
    _differences,
    _Misfit,
    _Parameters,
    tune_impulses,
)
from lumpbeam_ros.core.shaping.workspace import model_modes

MODEL = ArmModel.from_config(small_arm(2))


def test_the_window_from_the_end_state_matches_simulating_on():
    # A move that leaves millimetres of vibration, as a shaped one leaves at most; the map is
    # linear, so it misses the second-order part of the tip's motion (here about 5 um in x).
    move = minimum_jerk([0.0, 0.0], [0.2, -0.3], 0.6)
    end = float(move.time_s[-1])
    window = RestWindow.at(MODEL, move.angles_rad[-1], window_s=1.0)
    t = end + WINDOW_STEP_S * np.arange(window.samples)
    motion = simulate_arm(MODEL, SampledMotion(move), np.concatenate([[0.0], t]))
    rest = rest_tip(MODEL, move.angles_rad[-1])
    simulated = np.concatenate([motion.tip_x[1:] - rest[0], motion.tip_z[1:] - rest[1]])
    linear = window.deviations(motion.phi[1], motion.phi_dot[1])
    assert np.max(np.abs(simulated)) > 1e-3
    assert np.max(np.abs(linear - simulated)) < 0.01 * np.max(np.abs(simulated))


def test_one_impulse_has_nothing_to_tune():
    move = minimum_jerk([0.0, 0.0], [0.4, -0.6], 0.3)
    single = Impulses(np.array([0.0]), np.array([1.0]))
    assert tune_impulses(MODEL, move, single) is single


@pytest.mark.parametrize('budget', [3, 12])
def test_the_tuning_keeps_to_its_budget_and_its_bounds(budget):
    move = minimum_jerk([0.0, -1.0], [0.3, 1.0], 0.5)
    untuned = design_shaper('zv', [Mode(4.0, 0.02), Mode(11.0, 0.02)])
    tuned = tune_impulses(MODEL, move, untuned, max_simulations=budget)
    assert tuned.time_s[0] == 0.0 and tuned.duration_s == pytest.approx(untuned.duration_s)
    assert np.all(tuned.amplitude > 0) and tuned.amplitude.sum() == pytest.approx(1.0)


def test_the_linear_time_invariant_jacobian_is_the_differences_on_a_slow_small_move():
    # A slow small move is nearly linear and time-invariant: the cheap Jacobian (no
    # simulation) is then the one by differences (one simulation per unknown).
    move = minimum_jerk([0.0, 0.0], [0.05, -0.05], 0.8)
    window = RestWindow.at(MODEL, move.angles_rad[-1])
    misfit = _Misfit(MODEL, move, window)
    misfit(Impulses(np.zeros(1), np.ones(1)))
    unshaped_end = misfit.end_state
    modes = model_modes(MODEL, move.angles_rad[-1], 2, 'move')
    parameters = _Parameters(design_shaper('zvd', modes))
    cheap = parameters.lti_jacobian(window, unshaped_end)
    x = np.zeros(parameters.size)
    f = misfit(parameters.impulses(x))
    exact = _differences(misfit, parameters, x, f)
    assert np.linalg.norm(cheap - exact) < 0.05 * np.linalg.norm(exact)
