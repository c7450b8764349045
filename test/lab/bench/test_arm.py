"""The arm bench: its case (the config's arm, resampled), MuJoCo's steps, the quick suite."""

import numpy as np
import pytest

from lumpbeam_lab.bench.arm import RATE_HZ, _rk4_steps, arm_config, move, run
from lumpbeam_lab.bench.runner import available_suites
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.statics import arm_linear_model


def test_the_case_is_the_config_arm_with_its_taper_resampled():
    ten, thirty = arm_config(10), arm_config(30)
    assert [link.n_segments for link in thirty.links] == [30, 30, 30]
    assert ten.links[2].ei_nm2 == (
        2000.0,
        1900.0,
        1800.0,
        1700.0,
        1600.0,
        1500.0,
        1400.0,
        1300.0,
        1200.0,
        1100.0,
    )
    taper = np.array(thirty.links[2].ei_nm2)
    assert taper.size == 30 and np.all(np.diff(taper) <= 0.0)
    assert 1100.0 <= taper.min() and taper.max() <= 2000.0
    assert thirty.links[0].mass_kg == pytest.approx(ten.links[0].mass_kg)


def test_the_move_goes_from_rest_to_rest():
    motion = move(3, 2.0)
    assert motion.angles(0.0) == pytest.approx([0.0, 0.0, 0.0])
    assert motion.angles(2.0) == pytest.approx([0.6, -0.9, 0.7])
    assert motion.time_s.size == 2001


def test_mujocos_steps_divide_the_samples_inside_rk4s_stability_limit():
    model = ArmModel.from_config(arm_config(3))
    steps = _rk4_steps(model, np.zeros(3), 2)
    fastest = np.abs(np.linalg.eigvals(arm_linear_model(model, np.zeros(3)).state_matrix())).max()
    assert steps[0] * fastest <= 2.5 < 2 * steps[0] * fastest
    for step in steps:
        assert (1.0 / RATE_HZ / step) == pytest.approx(round(1.0 / RATE_HZ / step))
    assert steps[1] == pytest.approx(steps[0] / 2)


@pytest.mark.slow
def test_quick_suite_scores_ours_and_mujoco_against_the_reference():
    assert 'arm' in available_suites()
    against, cost = run(quick=True)
    assert against.unit == 's' and against.ratio == against.baseline_value / against.value
    assert against.details['tip_max_m'] < 1e-5
    assert against.details['mujoco_tip_max_m'] > 0.0
    assert 'LSODA rtol 1e-11' in against.details['reference']
    assert cost.details['method'] == 'modal' and cost.ratio > 0.0
