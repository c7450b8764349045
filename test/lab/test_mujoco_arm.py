"""The MuJoCo arm: one hinge per segment; its rollout is its step-by-step run."""

import numpy as np
import pytest
from arm_cases import small_arm, smooth_move

from lumpbeam_lab import mujoco_arm
from lumpbeam_lab.mujoco_arm import MujocoArm, arm_mjcf


def test_every_segment_is_a_body_on_a_hinge():
    config = small_arm(3)
    text = arm_mjcf(config, 1e-4)
    assert text.count('type="hinge"') == 10
    assert 'integrator="RK4"' in text
    assert MujocoArm(config, integrator='implicitfast').model.nv == 10


def test_the_rollout_in_mujocos_loop_is_the_step_by_step_run(monkeypatch):
    config = small_arm(3)
    move = smooth_move(np.array([-0.4, 0.9, 0.6]), 0.2)
    stepped = MujocoArm(config)
    stepped.equilibrium(move.angles(0.0))
    expected = stepped.run(lambda t: (move.angles(t), move.rates(t)), 0.3, 0.01)
    rolled = MujocoArm(config)
    rolled.equilibrium(move.angles(0.0))
    # Chunks that end between samples: the samples are picked across them.
    monkeypatch.setattr(mujoco_arm, 'ROLLOUT_CHUNK', 777)

    def drives(times):
        return (
            np.array([move.angles(t) for t in times]),
            np.array([move.rates(t) for t in times]),
        )

    got = rolled.rollout(drives, 0.3, 0.01)
    assert got['t'] == pytest.approx(expected['t'])
    assert got['x'] == pytest.approx(expected['x'], abs=1e-12)
    assert got['z'] == pytest.approx(expected['z'], abs=1e-12)
    assert float(got['wall_s']) > 0.0 and float(got['cpu_s']) >= 0.0


def test_a_moves_residual_in_mujoco_is_the_arm_models():
    from arm_cases import minimum_jerk

    from lumpbeam_ros.core.model.arm.model import ArmModel
    from lumpbeam_ros.core.model.arm.residual import WINDOW_S
    from lumpbeam_ros.core.shaping.workspace import predicted_residual

    config = small_arm(2)
    move = minimum_jerk([0.0, 0.0], [0.3, -0.4], 0.4)
    ours = predicted_residual(ArmModel.from_config(config), move)
    # The residual's 3 s window, as predicted_residual takes it.
    theirs = mujoco_arm.mujoco_residual(config, move, WINDOW_S)
    assert ours > 1e-3
    assert theirs == pytest.approx(ours, rel=1e-4)
