"""``lumpbeam analyze BAG... --arm FILE --fit-links``: the links from ring-downs, bad input."""

import json

import numpy as np
import pytest
import yaml
from arm_cases import small_arm, small_arm_document, write_move_bag

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.core.ident.arm.link_fit import link_stiffness_total

ONE = small_arm(1)
#: small_arm(1) with EI 20 % low and beta 30 % high: the nominal values the fit starts from.
NOMINAL_ONE = """
arm:
  payload_kg: 0.3
  links:
    - {length_m: 1.0, n_segments: 4, ei_nm2: 400.0, mass_kg: 1.0, damping_beta: 1.3e-3}
"""


@pytest.fixture(scope='module')
def bags(tmp_path_factory):
    root = tmp_path_factory.mktemp('fit_links')
    (root / 'one.yaml').write_text(NOMINAL_ONE)
    return {
        'arm': root / 'one.yaml',
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
        (['BAG_B'], 'several bags only with --fit-links'),
    ],
)
def test_options_that_do_not_go_together_exit_2(bags, capsys, extra, words):
    extra = [
        str(bags['arm']) if e == 'ARM' else str(bags['b']) if e == 'BAG_B' else e for e in extra
    ]
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
