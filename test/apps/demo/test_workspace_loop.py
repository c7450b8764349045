"""``lumpbeam demo --workspace``: the arm learned live, every later move shaped by it."""

import json
import math

import numpy as np
import pytest

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.apps.demo import workspace_loop as ws
from lumpbeam_ros.apps.demo.arm_graph import HOLD_S
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import ARM_STATUS
from lumpbeam_ros.base.resources import config_path
from lumpbeam_ros.core.bagio import BagReader
from lumpbeam_ros.core.bagio.series import read_diagnostics
from lumpbeam_ros.core.ident.arm.link_fit import link_stiffness_total
from lumpbeam_ros.core.model.arm.config import load_arm_config
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.shaping.loop import MoveResidual

NOMINAL = load_arm_config(config_path('arm_2link.yaml'))


def test_the_arm_itself_is_its_file_with_every_link_off():
    real = ws.real_arm(NOMINAL)
    for file, link, factor in zip(NOMINAL.links, real.links, ws.REAL_FACTORS, strict=True):
        assert link_stiffness_total(link) == pytest.approx(factor * link_stiffness_total(file))
        assert link.damping_beta == pytest.approx(file.damping_beta / factor)
        assert abs(factor - 1.0) == pytest.approx(0.2)
        assert link.mass_kg == file.mass_kg and link.length_m == file.length_m


def test_an_arm_of_another_number_of_links_is_refused_in_one_line():
    with pytest.raises(LumpbeamError, match='2-link arm; .* has 3') as caught:
        ws.real_arm(load_arm_config(config_path('arm_3link.yaml')))
    assert '\n' not in str(caught.value)


def test_the_moves_visit_five_configurations_within_the_joint_limits():
    moves = ws.workspace_moves()
    finals = [tuple(move.angles_rad[-1]) for move in moves]
    assert len(set(finals)) == len(moves) == 5 and (0.0, 0.0) not in finals
    start = np.zeros(2)
    for move, (target, duration) in zip(moves, ws.MOVES, strict=True):
        assert np.array_equal(move.angles_rad[0], start)  # from where the last one ended
        assert np.array_equal(move.angles_rad[-1], target)
        assert move.time_s[-1] == pytest.approx(HOLD_S + duration)
        NOMINAL.check_within_limits(move.angles_rad, 'the demo')
        start = move.angles_rad[-1]


def test_the_gap_is_the_slowest_decay_to_two_percent_within_its_bounds():
    model = ArmModel.from_config(NOMINAL)
    gaps = [ws.settle_gap(model, np.asarray(target)) for target, _ in ws.MOVES]
    assert all(ws.MIN_GAP_S <= gap <= ws.MAX_GAP_S for gap in gaps)
    # The first mode at (0.3, -0.4): 4.69 Hz, zeta 0.0147; exp(-zeta omega t) = 0.02.
    assert gaps[0] == pytest.approx(math.log(50.0) / (0.01472 * 2 * math.pi * 4.6918), rel=1e-3)


def _residual(value):
    return MoveResidual(None, value, (0.0, 0.0), np.zeros(2), np.zeros(2))


def _outcome(number, added_s, learned_from, measured, unshaped=1e-3):
    move = ws.workspace_moves()[number - 1]
    commanded = ws.CommandedMove(move, added_s, learned_from)
    return ws.MoveOutcome(number, commanded, _residual(measured), unshaped, 0.5 * unshaped)


@pytest.mark.parametrize(
    ('added_s', 'learned_from', 'label'),
    [
        (0.0, None, 'unshaped'),
        (1e-9, 2, 'unshaped'),  # a forward, its stamps rounded to the nanosecond
        (0.27, None, 'shaped'),
        (0.27, 1, 'learned (1 ring-down)'),
        (0.27, 3, 'learned (3 ring-downs)'),
    ],
)
def test_each_move_says_who_shaped_it(added_s, learned_from, label):
    assert _outcome(1, added_s, learned_from, 1e-4).shaped_by == label


def test_the_table_prints_each_moves_residuals_and_reduction():
    lines = ws.table([_outcome(1, 0.0, None, 1e-3), _outcome(4, 0.27, 2, 1e-5)])
    assert 'measured' in lines[1] and 'file model' in lines[1]
    assert '(0, 0) -> (0.3, -0.4) in 0.6 s' in lines[2] and 'unshaped' in lines[2]
    assert 'learned (2 ring-downs)' in lines[3] and '99.00%' in lines[3]


@pytest.mark.parametrize(
    ('outcomes', 'problem'),
    [
        ([_outcome(1, 0.0, None, 1e-3), _outcome(2, 0.0, None, 1e-3)], 'learned no arm'),
        ([_outcome(1, 0.0, None, 1e-3), _outcome(2, 0.27, 1, 2e-4)], 'move 2, .* 80.0 % less'),
    ],
    ids=['never learned', 'learned, too little'],
)
def test_the_summary_fails_when_learning_did_not_pay(tmp_path, outcomes, problem):
    run = ws.WorkspaceDemoRun(
        options=ws.WorkspaceDemoOptions(config_path('arm_2link.yaml'), out=tmp_path),
        nominal=NOMINAL,
        real=ws.real_arm(NOMINAL),
        echo=lambda _line: None,
        outcomes=outcomes,
    )
    with pytest.raises(LumpbeamError, match=problem) as caught:
        ws.summarize(run)
    assert '\n' not in str(caught.value)
    assert json.loads((tmp_path / 'summary.json').read_text())['moves'][0]['shaped_by']


@pytest.mark.parametrize(
    ('argv', 'problem'),
    [
        (['--workspace', '--seed', '3'], '--seed is an option of the drop-test demo, not of'),
        (['--workspace', '--arm', str(config_path('arm_3link.yaml'))], '2-link arm'),
    ],
)
def test_bad_options_stop_before_any_node_starts(tmp_path, capsys, argv, problem):
    assert main(['demo', *argv, '--out', str(tmp_path / 'out')]) == 2
    err = capsys.readouterr().err
    assert problem in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / 'out' / 'logs').exists()


# About a minute and a half: five moves, each waiting for its ring-down.
@pytest.mark.slow
@pytest.mark.ros
def test_the_workspace_demo_learns_the_arm_and_shapes_the_later_moves(tmp_path, capsys):
    out = tmp_path / 'results'
    code = main(['demo', '--workspace', '--out', str(out)])
    printed, err = capsys.readouterr()
    assert code == 0, f'{printed}\n{err}'
    summary = json.loads((out / 'summary.json').read_text())
    moves = summary['moves']
    assert len(moves) == 5 and moves[0]['shaped_by'] == 'unshaped'
    learned = [m for m in moves if m['shaped_by'].startswith('learned')]
    # Two ring-downs determine both links: the later moves are shaped by what they taught.
    assert len(learned) >= 2 and moves[-1] in learned
    for move in learned:
        assert move['reduction'] >= 0.95, move
        assert move['residual_m'] < move['residual_file_model_m'], move
    for move in moves:
        if move['shaped_by'] == 'unshaped':  # the arm's simulation from rest agrees
            assert move['residual_m'] == pytest.approx(move['residual_unshaped_m'], rel=0.1)
    # The links learned within 2 % of the arm's (the file is 20 % off).
    assert 'links learned from' in printed
    for line in printed.splitlines():
        if line.startswith('  link '):
            assert abs(float(line.rsplit(' ', 1)[1].rstrip('%'))) < 2.0, line
    # All of it in the bag, the arm's fits included.
    bag = summary['recorded_bag']
    counts = {name: entry.count for name, entry in BagReader(bag).topics.items()}
    assert counts['/joint_trajectory'] == counts['/joint_trajectory_shaped'] == 5
    statuses = [s for _, array in read_diagnostics(bag, '/arm_params') for s in array]
    assert any(s.name == ARM_STATUS and s.level == 0 for s in statuses)
    assert (out / 'figures' / ws.FIGURE_NAME).stat().st_size > 10_000
