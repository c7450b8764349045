"""The arm at rest and its modes: the beam's results, rotation invariance, moment balance."""

from dataclasses import replace

import numpy as np
import pytest
from arm_cases import paper_beam_arm, small_arm

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.statics import arm_equilibrium, arm_modes
from lumpbeam_ros.core.model.chain import LumpedChain
from lumpbeam_ros.core.model.modes import chain_modes
from lumpbeam_ros.core.model.parameters import load_beam_config
from lumpbeam_ros.core.model.statics import static_equilibrium

BEAM, _ = load_beam_config(None)


@pytest.mark.parametrize('n_segments', [1, 3, 10])
def test_the_one_link_arm_at_zero_has_the_beams_statics_and_modes(n_segments):
    beam = replace(BEAM, n_segments=n_segments)
    arm = ArmModel.from_config(paper_beam_arm(beam))
    chain = LumpedChain.from_beam(beam)
    assert arm_equilibrium(arm, np.zeros(1)) == pytest.approx(
        static_equilibrium(chain), rel=1e-9, abs=1e-12
    )
    ours, beams = arm_modes(arm, np.zeros(1)), chain_modes(chain)
    assert ours.natural_frequency_hz == pytest.approx(beams.natural_frequency_hz, rel=1e-9)
    assert ours.damping_ratio == pytest.approx(beams.damping_ratio, rel=1e-9)


def test_a_horizontal_arm_rests_straight_and_its_modes_ignore_joint_1():
    model = ArmModel.from_config(small_arm(3, plane='horizontal'))
    q = np.array([0.4, -1.1, 0.7])
    assert arm_equilibrium(model, q) == pytest.approx(model.rigid_angles(q), abs=1e-14)
    turned = arm_modes(model, q + np.array([1.3, 0.0, 0.0]))
    assert turned.natural_frequency_hz == pytest.approx(
        arm_modes(model, q).natural_frequency_hz, rel=1e-10
    )


def test_every_spring_carries_the_gravity_moment_of_what_lies_beyond_it():
    """Statics checked by moments about each spring's axis, from point positions alone."""
    model = ArmModel.from_config(small_arm(3))
    phi = arm_equilibrium(model, np.array([0.5, -1.2, 0.9]))
    chain = model.chain
    points = model.joint_points(phi)
    twist = np.diff(phi, prepend=0.0) - model.offsets(np.array([0.5, -1.2, 0.9]))
    torque = chain.stiffness * twist
    # Mass positions: segment centres, joint 2 and 3 masses, payload.
    centres = 0.5 * (points[:-1] + points[1:])
    others = [points[4], points[7], points[10]]
    positions = np.vstack([centres, others])
    owners = [*range(10), 3, 6, 9]  # the last segment each mass is carried by
    for j in range(chain.n):
        beyond = [p for p, owner in enumerate(owners) if owner >= j]
        # Gravity -z on mass p about spring j (at points[j]): a positive moment about +y turns
        # x toward -z, i.e. opposes a positive spring twist.
        levers = positions[beyond, 0] - points[j, 0]
        moment = (chain.masses[beyond] * chain.gravity * levers).sum()
        assert torque[j] == pytest.approx(moment, rel=1e-9)


def test_modes_are_complex_pairs_with_positive_damping():
    model = ArmModel.from_config(small_arm(3))
    modes = arm_modes(model, np.array([0.2, 0.3, -0.4]))
    assert 3 <= modes.natural_frequency_hz.size <= model.chain.n
    assert np.all(np.diff(modes.natural_frequency_hz) > 0)
    assert np.all((modes.damping_ratio > 0) & (modes.damping_ratio < 1))


def test_overdamped_modes_are_left_out():
    config = small_arm(2)
    heavy = replace(config, links=tuple(replace(link, damping_beta=0.01) for link in config.links))
    light = arm_modes(ArmModel.from_config(config), np.zeros(2))
    modes = arm_modes(ArmModel.from_config(heavy), np.zeros(2))
    assert 0 < modes.natural_frequency_hz.size < light.natural_frequency_hz.size
    assert np.all(modes.damping_ratio < 1)


def test_wrong_number_of_angles_is_an_error():
    model = ArmModel.from_config(small_arm(2))
    with pytest.raises(LumpbeamError, match='has 2 joints, got 3'):
        arm_equilibrium(model, np.zeros(3))


def test_an_arm_too_soft_for_its_load_is_an_error():
    config = small_arm(1)
    soft = replace(config, payload_kg=500.0)
    with pytest.raises(LumpbeamError, match='no static equilibrium'):
        arm_equilibrium(ArmModel.from_config(soft), np.zeros(1))
