"""Residuals of the moves in a record: an unshaped move rings, the shaped one after it not.

One record of the small rotary arm (horizontal, one link): a quick unshaped move, a rest,
and a move back shaped by ZV at the mode the arm's model gives, written as a synthetic bag
and read back, as the demo's loop would record it.
"""

import numpy as np
import pytest
from arm_cases import small_arm

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.residual import residual_rms, rest_tip
from lumpbeam_ros.core.model.arm.statics import arm_modes
from lumpbeam_ros.core.shaping.apply import shape_trajectory
from lumpbeam_ros.core.shaping.impulses import Mode
from lumpbeam_ros.core.shaping.loop import ShapingOutcome, bag_move_residuals, move_residuals
from lumpbeam_ros.core.shaping.shapers import design_shaper
from lumpbeam_ros.core.synthetic.arm_bag import ArmSynthOptions, write_arm_bag

ARM = small_arm(1, plane='horizontal')
MOVE_S, BACK_AT_S = 0.3, 4.0


def minimum_jerk(t, start, duration, height):
    s = np.clip((t - start) / duration, 0.0, 1.0)
    return height * (10 * s**3 - 15 * s**4 + 6 * s**5)


@pytest.fixture(scope='module')
def record(tmp_path_factory):
    model = ArmModel.from_config(ARM)
    modes = arm_modes(model, np.zeros(1))
    shaper = design_shaper('zv', [Mode(modes.natural_frequency_hz[0], modes.damping_ratio[0])])
    t = np.arange(0.0, MOVE_S + 1e-9, 1e-3)
    back = JointTrajectory(t, 0.5 - minimum_jerk(t, 0.0, MOVE_S, 0.5))
    back = shape_trajectory(back, shaper)
    times = np.concatenate([t, BACK_AT_S + back.time_s])
    angles = np.concatenate([minimum_jerk(t, 0.0, MOVE_S, 0.5), back.angles_rad[:, 0]])
    duration = BACK_AT_S + back.duration_s + 3.2
    out = tmp_path_factory.mktemp('loop') / 'bag'
    motion = write_arm_bag(
        out, ARM, JointTrajectory(times, angles), ArmSynthOptions(duration, noise_m=0.0)
    )
    return out, motion, BACK_AT_S + back.duration_s


def test_the_unshaped_move_rings_and_the_shaped_one_90_percent_less(record):
    bag, motion, shaped_end = record
    unshaped, shaped = bag_move_residuals(bag, ARM, topic='/tip_pose_truth')
    assert unshaped.move.end_s == pytest.approx(MOVE_S, abs=1 / 180)
    assert shaped.move.end_s == pytest.approx(shaped_end, abs=1 / 180)
    outcome = ShapingOutcome(unshaped, shaped)
    assert unshaped.residual_m > 1e-3
    assert outcome.reduction > 0.9
    print(f'\n{outcome.summary()}')
    assert 'unshaped' in outcome.summary() and '% less' in outcome.summary()


def test_each_move_is_judged_from_its_own_end_about_its_own_rest(record):
    _, motion, shaped_end = record
    first, second = move_residuals(ARM, motion.t, motion.q, motion.t, motion.tip_x, motion.tip_z)
    model = ArmModel.from_config(ARM)
    for residual, q, end in ((first, 0.5, MOVE_S), (second, 0.0, shaped_end)):
        rest = rest_tip(model, np.array([q]))
        want = residual_rms(motion.t, motion.tip_x, motion.tip_z, rest, end)
        assert residual.residual_m == pytest.approx(want, rel=1e-2)
        assert residual.rest == pytest.approx(rest)
        assert residual.t[0] == pytest.approx(0.0, abs=1 / 180)


def test_a_move_within_the_window_of_the_last_is_refused(record):
    _, motion, _ = record
    with pytest.raises(LumpbeamError, match='move 2 starts 4.000 s, within the 5 s after move 1'):
        move_residuals(ARM, motion.t, motion.q, motion.t, motion.tip_x, motion.tip_z, 5.0)
    with pytest.raises(LumpbeamError, match='never move'):
        move_residuals(ARM, motion.t, 0 * motion.q, motion.t, motion.tip_x, motion.tip_z)
