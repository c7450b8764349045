import json

import pytest

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.apps.plots.diagnosis import FIGURES
from lumpbeam_ros.core.bagio import BagWriter, read_tip_poses
from lumpbeam_ros.core.diagnose.candidates import SEARCHED_EFFECTS
from lumpbeam_ros.core.model.parameters import DropTestConfig, load_beam_config
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, write_drop_test_bag

from .helpers import rewritten

CONTRACT_KEYS = ['missing_effect', 'effect_parameters', 'gap_before', 'gap_after', 'candidates']


@pytest.fixture(scope='module')
def late_bag(tmp_path_factory):
    """A short drop test (4 s after the release) seen by a camera 15 ms late."""
    out = tmp_path_factory.mktemp('diagnose') / 'late'
    beam, _ = load_beam_config()
    options = SynthOptions(duration_s=6.0, seed=5, effects={'sensor_latency': 0.015})
    write_drop_test_bag(out, beam, DropTestConfig(duration_s=6.0), options)
    return out


def test_diagnose_writes_json_figures_and_a_model_that_reads_back(late_bag, tmp_path, capsys):
    json_path, plots, model = tmp_path / 'd.json', tmp_path / 'plots', tmp_path / 'aug.yaml'
    args = ['diagnose', str(late_bag), '--json', str(json_path), '--plots', str(plots)]
    assert main([*args, '--write-model', str(model)]) == 0
    printed = capsys.readouterr().out
    assert 'missing effect: sensor_latency' in printed
    assert 'gap before' in printed and 'gap after' in printed
    result = json.loads(json_path.read_text())
    assert list(result)[:5] == CONTRACT_KEYS
    assert result['missing_effect'] == 'sensor_latency'
    assert result['effect_parameters']['latency_s'] == pytest.approx(0.015, rel=0.1)
    assert result['gap_after']['rms_m'] < 0.3 * result['gap_before']['rms_m']
    assert len(result['candidates']) == len(SEARCHED_EFFECTS)
    assert [e['name'] for e in result['missing_effects']] == ['sensor_latency']
    assert all(set(c) == {'name', 'parameters', 'score'} for c in result['candidates'])
    for name in FIGURES:
        assert (plots / name).stat().st_size > 10_000
    beam, drop = load_beam_config(model)
    assert beam.effects.active() == {'sensor_latency': pytest.approx(0.015, rel=0.1)}
    assert beam.k_total_nm_per_rad == pytest.approx(3899.1, rel=0.02)
    assert drop.release_time_s == 2.0
    assert model.read_text().startswith('# Written by lumpbeam diagnose')


def test_a_creeping_mount_hidden_by_synth_is_named_by_diagnose(tmp_path, capsys):
    # The library's ninth effect, beyond the contract's eight: hidden in synthetic data by
    # the command line, found by it, with its rate, among all the other candidates.
    bag, json_path = tmp_path / 'creep', tmp_path / 'd.json'
    synth = ['synth', str(bag), '--effect', 'mount_creep=2e-5', '--duration', '6', '--seed', '7']
    assert main(synth) == 0
    assert main(['diagnose', str(bag), '--json', str(json_path)]) == 0
    assert 'missing effect: mount_creep' in capsys.readouterr().out
    result = json.loads(json_path.read_text())
    assert result['missing_effect'] == 'mount_creep'
    assert [e['name'] for e in result['missing_effects']] == ['mount_creep']
    assert result['effect_parameters']['rate_mps'] == pytest.approx(2e-5, rel=0.1)
    assert result['gap_after']['rms_m'] < 0.3 * result['gap_before']['rms_m']


def _write_still_bag(path):
    with BagWriter(path) as bag:
        bag.write_float('/tip_load', 0.0, 4.5)
        for i in range(1000):
            bag.write_pose('/tip_pose', i / 180.0, 2.3, -0.07, 0.04)


@pytest.mark.parametrize(
    ('setup', 'extra', 'message'),
    [
        (None, [], 'no such bag folder'),
        (_write_still_bag, [], 'never changes'),
        (_write_still_bag, ['--config', '/nonexistent/beam.yaml'], 'beam.yaml'),
    ],
)
def test_user_mistakes_are_one_line_errors(tmp_path, capsys, setup, extra, message):
    bag = tmp_path / 'bag'
    if setup is not None:
        setup(bag)
    assert main(['diagnose', str(bag), *extra]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert message in err


def test_a_bad_config_value_is_reported(tmp_path, late_bag, capsys):
    config = tmp_path / 'bad.yaml'
    config.write_text('/**:\n  ros__parameters:\n    beam:\n      length_m: -1.0\n')
    assert main(['diagnose', str(late_bag), '--config', str(config)]) == 2
    assert 'length_m' in capsys.readouterr().err


def _damaged(rows):
    for row in rows[100:110]:
        row[2] = float('nan')
    rows[200][0] = rows[199][0]  # a repeated stamp
    return rows


def test_dropped_poses_are_counted_on_stderr_and_in_the_json(late_bag, tmp_path, capsys):
    bag = rewritten(late_bag, tmp_path / 'damaged', _damaged)
    json_path = tmp_path / 'd.json'
    assert main(['diagnose', str(bag), '--json', str(json_path)]) == 0
    received = len(read_tip_poses(late_bag))
    warning = (
        f'lumpbeam diagnose: warning: {bag}: dropped 11 of {received} poses (10 with a NaN or '
        'inf stamp, position or orientation; 1 with a repeated or out-of-order stamp)'
    )
    assert warning in capsys.readouterr().err.splitlines()
    result = json.loads(json_path.read_text())
    assert (result['n_samples'], result['n_rejected']) == (received - 11, 11)


def test_a_bag_too_short_after_dropping_poses_says_why(late_bag, tmp_path, capsys):
    def mostly_nan(rows):
        for row in rows[:-300]:
            row[2] = float('nan')
        return rows

    bag = rewritten(late_bag, tmp_path / 'lost', mostly_nan)
    assert main(['diagnose', str(bag)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert 'need a longer record (dropped ' in err and 'with a NaN or inf stamp' in err


def test_each_named_effect_is_printed_beside_its_own_parameter():
    from types import SimpleNamespace

    from lumpbeam_ros.apps.cli.diagnose import verdict_text
    from lumpbeam_ros.core.diagnose.workflow import NamedEffect

    two = SimpleNamespace(
        missing_effect='coulomb_friction',
        missing_effects=(
            NamedEffect('coulomb_friction', {'torque_nm': 1.003}, 0.8),
            NamedEffect('sensor_latency', {'latency_s': 0.015}, 0.5),
        ),
    )
    assert verdict_text(two) == (
        'coulomb_friction (torque_nm = 1.003) + sensor_latency (latency_s = 0.015)'
    )
    assert verdict_text(SimpleNamespace(missing_effect='none', missing_effects=())) == 'none'
