"""The arm's chain: the paper beam is its one-link case; offsets, geometry, bad angles."""

import numpy as np
import pytest
from arm_cases import paper_beam_arm, small_arm

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.chain import LumpedChain
from lumpbeam_ros.core.model.parameters import load_beam_config

BEAM, _ = load_beam_config(None)


def test_the_one_link_arm_is_the_beams_chain():
    arm = ArmModel.from_config(paper_beam_arm(BEAM)).chain
    beam = LumpedChain.from_beam(BEAM)
    for name in ('inertia_coupling', 'gravity_moment', 'stiffness_matrix', 'damping_matrix'):
        assert getattr(arm, name) == pytest.approx(getattr(beam, name), rel=1e-12), name
    assert arm.inertia == pytest.approx(beam.inertia, rel=1e-12)
    assert arm.segment_lengths == pytest.approx(beam.segment_lengths)


def test_offsets_sit_on_each_links_first_spring():
    model = ArmModel.from_config(small_arm(3))
    assert model.link_starts.tolist() == [0, 4, 7]
    o = model.offsets(np.array([0.1, 0.2, 0.3]))
    assert np.flatnonzero(o).tolist() == [0, 4, 7]
    rigid = model.rigid_angles(np.array([0.1, 0.2, 0.3]))
    assert rigid == pytest.approx([0.1] * 4 + [0.3] * 3 + [0.6] * 3)


def test_joint_masses_ride_on_the_previous_links_end():
    model = ArmModel.from_config(small_arm(2))
    # Masses: 7 segment centres, joint 2's mass, the payload.
    chain = model.chain
    assert chain.masses[7:] == pytest.approx([0.8, 0.3])
    assert chain.levers[7] == pytest.approx([0.25] * 4 + [0.0] * 3)
    assert chain.levers[8] == pytest.approx([0.25] * 4 + [0.7 / 3] * 3)


def test_joint_points_end_at_the_tip_pose_and_follow_the_links():
    model = ArmModel.from_config(small_arm(3))
    phi = model.rigid_angles(np.array([0.3, -1.0, 0.5]))
    points = model.joint_points(phi)
    x, z, pitch = model.chain.tip_pose(phi)
    assert points[-1] == pytest.approx([x, z])
    # The undeflected arm: joint 2 at 1 m along 0.3 rad below +x.
    assert points[4] == pytest.approx([np.cos(0.3), -np.sin(0.3)])
    assert pitch == pytest.approx(-0.2)


@pytest.mark.parametrize(
    ('q', 'words'),
    [([0.1, 0.2], 'has 3 joints, got 2'), (0.5, 'got 1'), ([0.1, np.nan, 0.0], 'finite')],
)
def test_bad_joint_angles_are_one_line(q, words):
    model = ArmModel.from_config(small_arm(3))
    with pytest.raises(LumpbeamError, match=words):
        model.check_angles(np.asarray(q))
