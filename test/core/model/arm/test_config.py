"""The arm's configuration file: the contract's keys, the spring rules, every bad value."""

from pathlib import Path

import numpy as np
import pytest
import yaml

from lumpbeam_ros.base.errors import ConfigError, LumpbeamError
from lumpbeam_ros.core.model.arm.config import (
    arm_from_mapping,
    load_arm_config,
    write_arm_config,
)

LINK = {
    'length_m': 1.2,
    'n_segments': 4,
    'ei_nm2': 5000.6,
    'mass_kg': 1.9,
    'damping_beta': 2.2e-4,
    'joint_mass_kg': 0.0,
}


def _doc(**link_changes):
    link = {**LINK, **link_changes}
    link = {k: v for k, v in link.items() if v is not None}
    return {'arm': {'plane': 'vertical', 'payload_kg': 0.5, 'links': [LINK, link]}}


def test_reads_the_contract_example(tmp_path):
    path = tmp_path / 'arm.yaml'
    path.write_text(yaml.safe_dump(_doc()))
    arm = load_arm_config(path)
    assert arm.n_joints == 2 and arm.plane == 'vertical' and arm.payload_kg == 0.5
    link = arm.links[1]
    assert link.segment_masses_kg == pytest.approx([1.9 / 4] * 4)
    assert link.mass_kg == pytest.approx(1.9)
    assert arm.gravity_mps2 == 9.81
    assert arm.with_payload(2.0).payload_kg == 2.0


def test_uniform_ei_gives_the_papers_k_and_k_over_2():
    link = arm_from_mapping(_doc(), 'f').links[0]
    k = 2 * 5000.6 / 0.3  # B.9
    assert link.spring_stiffness() == pytest.approx([k, k / 2, k / 2, k / 2], rel=1e-14)
    assert link.spring_damping() == pytest.approx(2.2e-4 * link.spring_stiffness())


def test_varying_ei_puts_the_half_segments_in_series():
    ei = [4000.0, 3000.0, 2000.0, 1000.0]
    link = arm_from_mapping(_doc(ei_nm2=ei), 'f').links[1]
    ls = 0.3
    expected = [2 * ei[0] / ls] + [
        1 / (ls / (2 * a) + ls / (2 * b)) for a, b in zip(ei[:-1], ei[1:], strict=True)
    ]
    assert link.spring_stiffness() == pytest.approx(expected, rel=1e-14)


def test_identified_total_stiffness_is_n_s_k_te_then_half():
    link = arm_from_mapping(_doc(ei_nm2=None, k_total_nm_per_rad=3899.1), 'f').links[1]
    assert link.spring_stiffness() == pytest.approx([4 * 3899.1] + [2 * 3899.1] * 3)


def test_mass_list_is_per_segment_and_horizontal_has_no_gravity():
    doc = _doc(mass_kg=[0.4, 0.3, 0.2, 0.1])
    doc['arm']['plane'] = 'horizontal'
    arm = arm_from_mapping(doc, 'f')
    assert arm.links[1].segment_masses_kg == (0.4, 0.3, 0.2, 0.1)
    assert arm.gravity_mps2 == 0.0


@pytest.mark.parametrize(
    ('changes', 'key', 'words'),
    [
        ({'length_m': None}, 'arm.links[1].length_m', 'missing'),
        ({'length_m': -1.0}, 'arm.links[1].length_m', 'positive'),
        ({'n_segments': 0}, 'arm.links[1].n_segments', 'at least 1'),
        ({'n_segments': 2.5}, 'arm.links[1].n_segments', 'integer'),
        ({'ei_nm2': [1.0, 2.0]}, 'arm.links[1].ei_nm2', 'needs 4 values'),
        ({'ei_nm2': [1.0, 2.0, -3.0, 4.0]}, 'arm.links[1].ei_nm2[2]', 'positive'),
        ({'ei_nm2': None}, 'arm.links[1].ei_nm2', 'missing'),
        ({'k_total_nm_per_rad': 10.0}, 'arm.links[1].ei_nm2', 'exactly one'),
        ({'mass_kg': None}, 'arm.links[1].mass_kg', 'missing'),
        ({'mass_kg': 'heavy'}, 'arm.links[1].mass_kg', 'number'),
        ({'mass_kg': float('nan')}, 'arm.links[1].mass_kg', 'finite'),
        ({'damping_beta': -1e-4}, 'arm.links[1].damping_beta', 'negative'),
        ({'joint_mass_kg': -1.0}, 'arm.links[1].joint_mass_kg', 'negative'),
        ({'stiffness': 1.0}, 'arm.links[1].stiffness', 'unknown key'),
        ({'joint_limits_rad': 3.0}, 'arm.links[1].joint_limits_rad', '[LOW, HIGH]'),
        ({'joint_limits_rad': [1.0]}, 'arm.links[1].joint_limits_rad', '[LOW, HIGH]'),
        ({'joint_limits_rad': [1.0, -1.0]}, 'arm.links[1].joint_limits_rad', 'below'),
        ({'joint_limits_rad': [-1.0, 'up']}, 'arm.links[1].joint_limits_rad', 'number'),
    ],
)
def test_a_bad_link_value_is_one_line_naming_file_and_key(changes, key, words):
    with pytest.raises(ConfigError) as info:
        arm_from_mapping(_doc(**changes), 'arm.yaml')
    message = str(info.value)
    assert message.startswith(f'arm.yaml: {key}: ') and words in message
    assert '\n' not in message


@pytest.mark.parametrize(
    ('doc', 'key', 'words'),
    [
        ({'arm': {'plane': 'diagonal', 'links': [LINK]}}, 'arm.plane', 'one of'),
        ({'arm': {'payload_kg': -0.5, 'links': [LINK]}}, 'arm.payload_kg', 'negative'),
        ({'arm': {'links': []}}, 'arm.links', 'non-empty'),
        ({'arm': {'links': [3.0]}}, 'arm.links[0]', 'mapping'),
        ({'arm': {'links': [LINK], 'speed': 1}}, 'arm.speed', 'unknown key'),
        ({'beam': {}}, 'arm', 'missing'),
        ([1, 2], 'arm', 'missing'),
        ({'arm': {'links': [LINK]}, 'extra': 1}, 'extra', 'unknown key'),
    ],
)
def test_a_bad_arm_is_one_line(doc, key, words):
    with pytest.raises(ConfigError) as info:
        arm_from_mapping(doc, 'arm.yaml')
    assert str(info.value).startswith(f'arm.yaml: {key}: ') and words in str(info.value)


def test_missing_and_broken_files(tmp_path):
    with pytest.raises(ConfigError, match='no such file'):
        load_arm_config(tmp_path / 'none.yaml')
    broken = tmp_path / 'broken.yaml'
    broken.write_text('arm: [unclosed\n')
    with pytest.raises(ConfigError, match='not valid YAML'):
        load_arm_config(broken)


@pytest.mark.parametrize(('name', 'joints'), [('arm_rotary.yaml', 1), ('arm_3link.yaml', 3)])
def test_the_example_configurations_load(name, joints):
    arm = load_arm_config(Path(__file__).resolve().parents[4] / 'config' / name)
    assert arm.n_joints == joints


@pytest.mark.parametrize(
    'changes',
    [
        {},
        {'ei_nm2': [4000.0, 3000.0, 2000.0, 1000.5], 'mass_kg': [0.4, 0.3, 0.2, 0.1]},
        {'ei_nm2': None, 'k_total_nm_per_rad': 1234.5, 'joint_limits_rad': [-2.5, 1.25]},
    ],
    ids=['uniform', 'lists', 'k_total and limits'],
)
def test_a_written_arm_reads_back_the_same(tmp_path, changes):
    arm = arm_from_mapping(_doc(**changes), 'f')
    path = tmp_path / 'out.yaml'
    write_arm_config(path, arm, header='fitted\nfrom two bags')
    assert path.read_text().startswith('# fitted\n# from two bags\n')
    again = load_arm_config(path)
    assert again.plane == arm.plane and again.payload_kg == arm.payload_kg
    for read, written in zip(again.links, arm.links, strict=True):
        assert read.segment_masses_kg == pytest.approx(written.segment_masses_kg, rel=1e-15)
        assert read.spring_stiffness() == pytest.approx(written.spring_stiffness(), rel=1e-15)
        assert (read.damping_beta, read.joint_limits_rad) == (
            written.damping_beta,
            written.joint_limits_rad,
        )


def test_an_arm_file_that_cannot_be_written_is_one_line(tmp_path):
    arm = arm_from_mapping(_doc(), 'f')
    with pytest.raises(LumpbeamError, match='cannot write the arm file'):
        write_arm_config(tmp_path / 'no' / 'such' / 'dir.yaml', arm)


def test_angles_outside_a_joints_limits_are_refused_naming_the_joint():
    arm = arm_from_mapping(_doc(joint_limits_rad=[-1.0, 1.0]), 'arm.yaml')
    arm.check_within_limits(np.array([[5.0, 0.5], [-5.0, -1.0]]), 'IN.csv')
    with pytest.raises(LumpbeamError) as info:
        arm.check_within_limits(np.array([[0.0, 0.5], [0.0, 1.2]]), 'IN.csv')
    assert str(info.value) == (
        'IN.csv: joint_2 at 1.2 rad is outside its limits [-1, 1] rad (arm.yaml)'
    )
