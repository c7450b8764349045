"""The link-fit trials: noiseless measurements score zero error, the table's figures."""

from dataclasses import replace

import numpy as np
import pytest

from lumpbeam_lab.arm_links import (
    CASES,
    FINISH_S,
    MOVE_S,
    PAUSE_S,
    ArmCase,
    Trials,
    campaign_move,
    main,
    nominal_arm,
    observations,
    run_bag_trials,
    run_trials,
    truth_table,
)
from lumpbeam_ros.core.ident.arm.link_fit import LinkParameterFit
from lumpbeam_ros.core.model.arm.config import load_arm_config

ROTARY, THREE = CASES


def test_the_nominal_arm_is_20_percent_off_every_value():
    truth = load_arm_config(ROTARY.config)
    nominal = nominal_arm(truth, np.random.default_rng(0))
    ratio = truth_table(nominal) / truth_table(truth)
    assert np.abs(ratio - 1) == pytest.approx(np.full_like(ratio, 0.2))


def test_noiseless_modes_score_no_error():
    truth = load_arm_config(ROTARY.config)
    obs = observations(truth, ROTARY, None)
    assert [len(o.modes) for o in obs] == [2, 2]
    fit = LinkParameterFit(nominal_arm(truth, np.random.default_rng(3))).fit(obs)
    got = np.array([[e.k_total_nm_per_rad, e.damping_beta] for e in fit.links])
    assert got == pytest.approx(truth_table(truth), rel=1e-6)


def test_the_table_reports_errors_and_coverage(capsys):
    case = ArmCase('rotary', ROTARY.config, ((0.3,),), 1)
    result = run_trials(case, trials=2, seed=1)
    assert isinstance(result, Trials) and result.values.shape == (2, 1, 2)
    rows = result.rows()
    assert len(rows) == 2 and 'within 3 std 2/2' in rows[0] and 'RMS' in rows[0]
    assert main(['--trials', '1', '--only', 'rotary']) == 0
    assert 'link 1 k_total' in capsys.readouterr().out


def test_each_campaign_move_ends_with_the_cases_quick_step():
    q = np.array([0.3, -0.4, 0.2])
    move = campaign_move(THREE, q)
    angles, t = move.angles_rad, move.time_s
    assert angles[0] == pytest.approx(np.zeros(3)) and angles[-1] == pytest.approx(q)
    step = t >= t[-1] - FINISH_S
    assert t[-1] == pytest.approx(MOVE_S + PAUSE_S + FINISH_S)
    # Only the wrist moves in the last 0.15 s, by the case's step; before it the arm rests.
    assert angles[step][0] == pytest.approx(q - np.array(THREE.finish))
    assert np.ptp(angles[step], axis=0) == pytest.approx(np.abs(THREE.finish))
    plain = campaign_move(replace(THREE, finish=()), q)
    assert plain.time_s[-1] == pytest.approx(MOVE_S) and plain.angles_rad[-1] == pytest.approx(q)


@pytest.mark.slow
def test_a_campaign_from_bags_recovers_the_rotary_link(tmp_path):
    result = run_bag_trials(ROTARY, tmp_path, trials=1, seed=2)
    err = np.abs(result.trials.values[0] / result.trials.truth - 1)
    assert np.all(err < 0.01) and np.all(err <= 3 * result.trials.stds[0] / result.trials.truth)
    assert result.modes.tolist() == [len(ROTARY.finals)] and list(tmp_path.iterdir()) == []
    (rows,) = result.mode_errors.values()
    assert rows.shape == (2, 4) and np.all(np.abs(rows[:, 2]) <= 3 * rows[:, 3])
    assert result.mode_rows()[0].startswith('  mode 1 in 2/2 bags: frequency error %')


def test_repeated_configurations_are_trials_on_more_bags(capsys):
    assert main(['--trials', '1', '--only', 'rotary', '--repeat', '2']) == 0
    assert '2 configurations x 2 modes, each in 2 bags' in capsys.readouterr().out
    with pytest.raises(SystemExit) as exit_info:
        main(['--repeat', '0'])
    assert exit_info.value.code == 2
    assert '--repeat 0: at least 1' in capsys.readouterr().err
