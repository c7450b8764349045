"""An arm bag's final joints and ring-down modes, and the bags refused for a link fit."""

import numpy as np
import pytest

from arm.arm_cases import small_arm, write_move_bag
from lumpbeam_ros.arm.bag_modes import (
    bag_observation,
    bag_observations,
    read_final_joints,
    read_joint_states,
    ringdown_modes,
)
from lumpbeam_ros.arm.link_fit import MeasuredMode
from lumpbeam_ros.arm.model import ArmModel
from lumpbeam_ros.arm.statics import arm_modes
from lumpbeam_ros.bagio import BagWriter
from lumpbeam_ros.errors import BagError, LumpbeamError

ONE = small_arm(1)


@pytest.fixture(scope='module')
def bags(tmp_path_factory):
    root = tmp_path_factory.mktemp('arm_bags')
    return {
        'a': write_move_bag(root / 'a', ONE, [0.5]),
        'b': write_move_bag(root / 'b', ONE, [-0.4]),
        'two': write_move_bag(root / 'two', small_arm(2), [0.3, -0.2], record_s=1.5),
        'renamed': write_move_bag(root / 'renamed', ONE, [0.2], record_s=1.5, names=['shoulder']),
        'short': write_move_bag(root / 'short', ONE, [0.5], record_s=0.9),
    }


def test_the_joints_rest_at_their_final_angles_from_the_moves_end(bags):
    joints = read_final_joints(bags['a'])
    assert joints.names == ('joint_1',)
    assert joints.angles_rad == pytest.approx([0.5], abs=1e-12)
    assert joints.rest_from_s == pytest.approx(0.5, abs=1.0 / 180)
    assert joints.end_s == pytest.approx(4.0, abs=1.0 / 180)


def test_the_ring_down_gives_the_truths_first_mode(bags):
    observation = bag_observation(bags['a'])
    truth = arm_modes(ArmModel.from_config(ONE), np.array([0.5]))
    first = observation.modes[0]
    assert abs(first.natural_frequency_hz - truth.natural_frequency_hz[0]) < 5 * max(
        first.natural_frequency_hz_std, 1e-4 * truth.natural_frequency_hz[0]
    )
    assert first.damping_ratio == pytest.approx(truth.damping_ratio[0], rel=0.1)
    assert observation.label == str(bags['a'])


def test_noise_alone_has_no_mode():
    rng = np.random.default_rng(0)
    t = np.arange(0, 3, 1 / 180)
    assert (
        ringdown_modes(t, 20e-6 * rng.standard_normal(t.size), 20e-6 * rng.standard_normal(t.size))
        == ()
    )


def test_bags_from_another_arm_are_refused(bags):
    with pytest.raises(LumpbeamError, match=r'two: /joint_states has 2 joint\(s\), the arm .* 1'):
        bag_observations([bags['a'], bags['two']], ONE)
    with pytest.raises(LumpbeamError, match=r"renamed: /joint_states names \['shoulder'\]"):
        bag_observations([bags['a'], bags['renamed']], ONE)


def test_a_bag_without_a_ring_down_or_joints_is_refused(bags, tmp_path):
    with pytest.raises(BagError, match='short: no ring-down after the last move'):
        bag_observations([bags['short']], ONE)
    with BagWriter(tmp_path / 'beam') as writer:
        writer.write_pose('/tip_pose', 0.0, 1.0, 0.0, 0.0)
    with pytest.raises(BagError, match=r'beam: no /joint_states in the bag: not a moving arm'):
        read_final_joints(tmp_path / 'beam')


def test_joint_states_that_change_names_are_refused(tmp_path):
    with BagWriter(tmp_path / 'mixed') as writer:
        writer.write_joint_state('/joint_states', 0.0, ['joint_1'], np.zeros(1))
        writer.write_joint_state('/joint_states', 0.1, ['joint_2'], np.zeros(1))
    with pytest.raises(BagError, match='names change'):
        read_final_joints(tmp_path / 'mixed')


def test_a_joint_state_recorded_twice_counts_once(tmp_path):
    with BagWriter(tmp_path / 'twice') as writer:
        for stamp, angle in ((0.0, 0.0), (0.1, 0.2), (0.1, 0.2), (0.2, 0.2)):
            writer.write_joint_state('/joint_states', stamp, ['joint_1'], np.array([angle]))
    joints = read_joint_states(tmp_path / 'twice')
    assert joints.t == pytest.approx([0.0, 0.1, 0.2])
    assert read_final_joints(tmp_path / 'twice').rest_from_s == pytest.approx(0.1)


def test_another_identifier_plugs_into_the_seam(bags):
    seen = {}

    def identify(t, x, z, max_modes):
        seen.update(start=t[0], count=t.size, max_modes=max_modes)
        return [MeasuredMode(2.0, 0.01, 0.02, 0.001)]

    (observation,) = bag_observations([bags['a']], ONE, max_modes=5, identify=identify)
    assert observation.modes == (MeasuredMode(2.0, 0.01, 0.02, 0.001),)
    assert seen['start'] == pytest.approx(0.5, abs=1 / 180) and seen['max_modes'] == 5
    with pytest.raises(BagError, match='no mode stands out of the noise'):
        bag_observation(bags['a'], identify=lambda *_: [])
