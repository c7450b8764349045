"""An arm bag's final joints and ring-down modes, and the bags refused for a link fit."""

import numpy as np
import pytest
from arm_cases import small_arm, write_move_bag

from lumpbeam_ros.base.errors import BagError, LumpbeamError
from lumpbeam_ros.core.bagio import BagWriter
from lumpbeam_ros.core.ident.arm.bag_modes import bag_observation, bag_observations
from lumpbeam_ros.core.ident.settings import IdentifierConfig
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.statics import arm_modes

ONE = small_arm(1)
CONFIG = IdentifierConfig()


@pytest.fixture(scope='module')
def bags(tmp_path_factory):
    root = tmp_path_factory.mktemp('arm_bags')
    return {
        'a': write_move_bag(root / 'a', ONE, [0.5]),
        'two': write_move_bag(root / 'two', small_arm(2), [0.3, -0.2], record_s=1.5),
        'renamed': write_move_bag(root / 'renamed', ONE, [0.2], record_s=1.5, names=['shoulder']),
        'short': write_move_bag(root / 'short', ONE, [0.5], record_s=0.6),
    }


def test_the_ring_down_gives_the_truths_first_mode_at_the_final_angles(bags):
    observation = bag_observation(bags['a'], ONE, CONFIG)
    assert observation.joint_angles_rad == pytest.approx([0.5], abs=1e-12)
    truth = arm_modes(ArmModel.from_config(ONE), np.array([0.5]))
    first = observation.modes[0]
    assert abs(first.natural_frequency_hz - truth.natural_frequency_hz[0]) < 5 * max(
        first.natural_frequency_hz_std, 1e-4 * truth.natural_frequency_hz[0]
    )
    assert first.damping_ratio == pytest.approx(truth.damping_ratio[0], rel=0.1)
    assert observation.label == str(bags['a'])


def test_bags_from_another_arm_are_refused(bags):
    with pytest.raises(LumpbeamError, match=r'two: /joint_states has 2 joint\(s\), the arm .* 1'):
        bag_observations([bags['a'], bags['two']], ONE, CONFIG)
    with pytest.raises(LumpbeamError, match=r"renamed: /joint_states names \['shoulder'\]"):
        bag_observations([bags['a'], bags['renamed']], ONE, CONFIG)


def test_a_bag_without_a_ring_down_or_joints_is_refused(bags, tmp_path):
    with pytest.raises(LumpbeamError, match='short'):
        bag_observations([bags['short']], ONE, CONFIG)
    with BagWriter(tmp_path / 'beam') as writer:
        writer.write_pose('/tip_pose', 0.0, 1.0, 0.0, 0.0)
    with pytest.raises(BagError, match=r"beam.*/joint_states.*not a moving arm's record"):
        bag_observations([tmp_path / 'beam'], ONE, CONFIG)
