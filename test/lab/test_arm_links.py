"""The link-fit trials: noiseless measurements score zero error, the table's figures."""

import numpy as np
import pytest

from lumpbeam_lab.arm_links import (
    CASES,
    ArmCase,
    Trials,
    main,
    nominal_arm,
    observations,
    run_trials,
    truth_table,
)
from lumpbeam_ros.arm.config import load_arm_config
from lumpbeam_ros.arm.link_fit import LinkParameterFit

ROTARY = CASES[0]


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
