"""``lumpbeam analyze BAG... --arm FILE --fit-links|--fit-payload [--write-arm]``, bad input."""

import json

import numpy as np
import pytest
import yaml
from arm_cases import small_arm, small_arm_document, write_move_bag

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.core.ident.arm.link_fit import link_stiffness_total
from lumpbeam_ros.core.model.arm.config import load_arm_config

ONE = small_arm(1)
#: small_arm(1) with EI 20 % low and beta 30 % high: the nominal values the fit starts from.
NOMINAL_ONE = """
arm:
  payload_kg: 0.3
  links:
    - {length_m: 1.0, n_segments: 4, ei_nm2: 400.0, mass_kg: 1.0, damping_beta: 1.3e-3}
"""
#: small_arm(1)'s links, without the part it carries (0.3 kg): what --fit-payload starts from.
EMPTY_ONE = """
arm:
  payload_kg: 0.0
  links:
    - {length_m: 1.0, n_segments: 4, ei_nm2: 500.0, mass_kg: 1.0, damping_beta: 1.0e-3}
"""


@pytest.fixture(scope='module')
def bags(tmp_path_factory):
    root = tmp_path_factory.mktemp('fit_links')
    (root / 'one.yaml').write_text(NOMINAL_ONE)
    (root / 'empty.yaml').write_text(EMPTY_ONE)
    return {
        'arm': root / 'one.yaml',
        'empty': root / 'empty.yaml',
        'a': write_move_bag(root / 'a', ONE, [0.5]),
        'b': write_move_bag(root / 'b', ONE, [-0.4]),
        'three': write_move_bag(root / 'three', small_arm(3), [0.6, 0.2, 0.4], record_s=2.5),
        'short': write_move_bag(root / 'short', ONE, [0.5], record_s=0.55),
    }


def test_fits_the_link_within_5_percent_from_20_percent_off(bags, tmp_path, capsys):
    out = tmp_path / 'links.json'
    argv = ['analyze', str(bags['a']), str(bags['b']), '--arm', str(bags['arm'])]
    assert main([*argv, '--fit-links', '--json', str(out)]) == 0
    assert 'link 1: k_total' in capsys.readouterr().out
    data = json.loads(out.read_text())
    (link,) = data['links']
    assert set(link) == {
        'k_total_nm_per_rad',
        'k_total_nm_per_rad_std',
        'damping_beta',
        'damping_beta_std',
    }
    truth = ONE.links[0]
    assert link['k_total_nm_per_rad'] == pytest.approx(link_stiffness_total(truth), rel=0.05)
    assert link['damping_beta'] == pytest.approx(truth.damping_beta, rel=0.05)
    assert 0 < link['k_total_nm_per_rad_std'] < 0.05 * link['k_total_nm_per_rad']
    assert [b['joint_angles_rad'] for b in data['bags']] == [[0.5], [-0.4]]
    assert np.isfinite(data['chi2'])


@pytest.mark.parametrize(
    ('extra', 'words'),
    [
        (['--fit-links'], '--fit-links needs --arm FILE'),
        (['BAG_B'], 'several bags only with --fit-links or --fit-payload'),
        (['--fit-payload'], '--fit-payload needs --arm FILE'),
        (['--arm', 'ARM', '--fit-links', '--fit-payload'], 'not both'),
        (['--arm', 'ARM', '--write-arm', 'OUT'], '--write-arm needs --fit-links or --fit-payload'),
    ],
)
def test_options_that_do_not_go_together_exit_2(bags, capsys, extra, words):
    names = {'ARM': str(bags['arm']), 'BAG_B': str(bags['b']), 'OUT': 'out.yaml'}
    extra = [names.get(e, e) for e in extra]
    assert main(['analyze', str(bags['a']), *extra]) == 2
    err = capsys.readouterr().err
    assert words in err and err.count('\n') == 1


@pytest.mark.parametrize(
    ('names', 'words'),
    [
        (['a', 'three'], 'three: /joint_states has 3 joint(s), the arm'),
        (['short'], 'short: the joints rest at most 0.0556 s after a move, need 0.278 s'),
    ],
)
def test_bags_from_another_arm_or_without_ring_down_exit_2(bags, capsys, names, words):
    argv = ['analyze', *(str(bags[n]) for n in names), '--arm', str(bags['arm']), '--fit-links']
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert words in err and err.count('\n') == 1


def test_one_bag_where_the_links_need_more_configurations_exits_2(bags, tmp_path, capsys):
    arm = tmp_path / 'three.yaml'
    arm.write_text(yaml.safe_dump(small_arm_document(3)))
    # Two modes of one configuration for three links: more unknowns than the data hold.
    argv = ['analyze', str(bags['three']), '--arm', str(arm), '--fit-links', '--max-modes', '2']
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert 'the 3 links need at least 3' in err and err.count('\n') == 1


def test_the_fitted_links_are_written_as_an_arm_file(bags, tmp_path, capsys):
    out = tmp_path / 'fitted.yaml'
    argv = ['analyze', str(bags['a']), str(bags['b']), '--arm', str(bags['arm'])]
    assert main([*argv, '--fit-links', '--write-arm', str(out)]) == 0
    assert f'wrote {out}' in capsys.readouterr().out
    fitted, nominal = load_arm_config(out), load_arm_config(bags['arm'])
    truth = ONE.links[0]
    link = fitted.links[0]
    # An EI link stays an EI link, scaled; everything else is the file's.
    assert link.ei_nm2 is not None
    assert link.ei_nm2[0] == pytest.approx(truth.ei_nm2[0], rel=0.05)
    assert link.damping_beta == pytest.approx(truth.damping_beta, rel=0.05)
    assert fitted.payload_kg == nominal.payload_kg
    assert link.segment_masses_kg == pytest.approx(nominal.links[0].segment_masses_kg)
    assert out.read_text().startswith('# lumpbeam analyze: links fitted to the bags')


def test_the_payload_is_fitted_and_written(bags, tmp_path, capsys):
    out, arm_out = tmp_path / 'payload.json', tmp_path / 'loaded.yaml'
    argv = ['analyze', str(bags['a']), str(bags['b']), '--arm', str(bags['empty'])]
    assert main([*argv, '--fit-payload', '--json', str(out), '--write-arm', str(arm_out)]) == 0
    assert ': payload 0.299' in capsys.readouterr().out
    data = json.loads(out.read_text())
    assert data['payload_kg'] == pytest.approx(ONE.payload_kg, rel=0.02)
    assert 0 < data['payload_kg_std'] < 0.05 * data['payload_kg']
    assert abs(data['payload_kg'] - ONE.payload_kg) < 4 * data['payload_kg_std']
    assert load_arm_config(arm_out).payload_kg == data['payload_kg']


def test_a_payload_the_modes_ask_to_be_negative_is_refused(bags, tmp_path, capsys):
    # The file's link is 60 % softer than the arm's: only a negative payload would match.
    soft = tmp_path / 'soft.yaml'
    soft.write_text(EMPTY_ONE.replace('ei_nm2: 500.0', 'ei_nm2: 200.0'))
    argv = ['analyze', str(bags['a']), str(bags['b']), '--arm', str(soft)]
    assert main([*argv, '--fit-payload']) == 2
    err = capsys.readouterr().err
    assert 'ask for a negative payload' in err and err.count('\n') == 1


def test_a_payload_fit_the_model_cannot_match_is_warned_about(bags, tmp_path, capsys):
    # The file's link is 20 % softer: a payload of about 0.19 kg, but the two configurations
    # then disagree far beyond their noise.
    argv = ['analyze', str(bags['a']), str(bags['b']), '--arm', str(bags['arm'])]
    assert main([*argv, '--fit-payload']) == 0
    err = capsys.readouterr().err
    assert 'matches the modes poorly with any payload' in err and err.count('\n') == 1
