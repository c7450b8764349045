import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from ring_downs import MODES, ring_down, write_bag

from lumpbeam_lab.ident.taps import Tap
from lumpbeam_ros.apps.cli.analyze import CONTRACT_KEYS
from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.base.resources import config_path
from lumpbeam_ros.core.bagio import BagWriter
from lumpbeam_ros.core.model.chain import LumpedChain
from lumpbeam_ros.core.model.modes import chain_modes
from lumpbeam_ros.core.model.parameters import BeamParameters, DropTestConfig
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, write_drop_test_bag

from .helpers import rewritten

#: ``lumpbeam analyze --json`` of the default synthetic drop test as it was before the result
#: was nested (and its ``/beam_params`` pairs): the contract's keys, their order and values.
GOLDEN = json.loads((Path(__file__).parents[2] / 'data' / 'analyze_drop_golden.json').read_text())


@pytest.fixture(scope='module')
def drop_bag(tmp_path_factory):
    bag = tmp_path_factory.mktemp('analyze') / 'drop'
    write_drop_test_bag(bag, BeamParameters(), DropTestConfig(), SynthOptions())
    return bag


def test_analyze_prints_writes_json_and_plots(drop_bag, tmp_path, capsys):
    out = tmp_path / 'result.json'
    plots = tmp_path / 'plots'
    assert main(['analyze', str(drop_bag), '--json', str(out), '--plots', str(plots)]) == 0
    text = capsys.readouterr().out
    assert 'status: OK' in text and 'natural frequency: 3.0588 +-' in text
    data = json.loads(out.read_text())
    truth = chain_modes(LumpedChain.from_beam(BeamParameters(), 0.0))
    for key in CONTRACT_KEYS:
        assert data[key] > 0 and data[f'{key}_std'] > 0
    assert abs(data['natural_frequency_hz'] - truth.natural_frequency_hz[0]) < (
        3 * data['natural_frequency_hz_std']
    )
    assert data['release_time_s'] == pytest.approx(2.0, abs=0.2 / 180.0)
    assert data['status'] == 'OK'
    assert data['static_deflection_m'] == pytest.approx(0.04044, rel=1e-3)
    # The beam's own k_tE within 3 standard deviations: B.12's share of the error in them.
    truth = BeamParameters().k_total_nm_per_rad
    assert (
        abs(data['stiffness_total_nm_per_rad'] - truth)
        < 3 * data['stiffness_total_nm_per_rad_std']
    )
    assert sorted(p.name for p in plots.iterdir()) == [
        'estimates.png',
        'spectrum.png',
        'trajectory.png',
    ]


def same_value(value, expected):
    """Equal, floats to 1e-6 relative.

    The uncertainties and the amplitude shift are small differences of large sums: another
    numpy, BLAS or CPU rounds them a few 1e-9 apart (seen on CI), while any real change in the
    estimators moves them by far more than 1e-6.
    """
    if isinstance(expected, float):
        return value == pytest.approx(expected, rel=1e-6, abs=1e-300)
    return value == expected


def test_analyze_json_keeps_the_keys_their_order_and_values(drop_bag, tmp_path):
    out = tmp_path / 'result.json'
    assert main(['analyze', str(drop_bag), '--json', str(out)]) == 0
    data = json.loads(out.read_text())
    expected = GOLDEN['analyze_json']
    # The modes came later, after every golden key, then the record's free vibrations and
    # steady lines; the top-level keys are the first mode's.
    assert list(data) == [*expected, 'modes', 'events', 'lines']
    assert set(CONTRACT_KEYS) | {f'{key}_std' for key in CONTRACT_KEYS} <= set(data)
    assert [key for key in expected if not same_value(data[key], expected[key])] == []
    # The drop's second mode (35 Hz, about 20 um at the start, damped in 0.1 s) is under the
    # 20 um noise: one mode, the top-level one.
    assert data['modes'] == [
        {
            'natural_frequency_hz': data['natural_frequency_hz'],
            'natural_frequency_hz_std': data['natural_frequency_hz_std'],
            'damping_ratio': data['damping_ratio'],
            'damping_ratio_std': data['damping_ratio_std'],
            'amplitude_m': data['amplitude_m'],
        }
    ]
    # One free vibration, the release's, with the same modes; no steady line.
    [event] = data['events']
    assert event['kind'] == 'release' and event['modes'] == data['modes']
    assert event['start_s'] == data['release_time_s'] and data['lines'] == []


def _bag(path, poses=(), frame='beam_base', loads=()):
    with BagWriter(path) as bag:
        for t, z in poses:
            bag.write_pose('/tip_pose', t, 2.3, z, 0.0, frame=frame)
        for t, kg in loads:
            bag.write_float('/tip_load', t, kg)
    return path


def _error_line(capsys):
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith('lumpbeam analyze: error: ')
    return err[0]


def test_bag_without_tip_pose(tmp_path, capsys):
    bag = _bag(tmp_path / 'b', loads=[(0.0, 4.5)])
    assert main(['analyze', str(bag)]) == 2
    assert 'no /tip_pose in the bag (it has /tip_load)' in _error_line(capsys)


def test_poses_in_another_frame(tmp_path, capsys):
    bag = _bag(tmp_path / 'b', poses=[(i / 180, -0.03) for i in range(100)], frame='camera')
    assert main(['analyze', str(bag)]) == 2
    assert "frame 'camera', expected 'beam_base'" in _error_line(capsys)


def test_folder_that_is_not_a_bag_and_missing_bag(tmp_path, capsys):
    (tmp_path / 'plain').mkdir()
    assert main(['analyze', str(tmp_path / 'plain')]) == 2
    assert 'not a rosbag2 bag' in _error_line(capsys)
    assert main(['analyze', str(tmp_path / 'nope')]) == 2
    assert 'no such bag' in _error_line(capsys)


def test_empty_and_too_short_bags(tmp_path, capsys):
    with BagWriter(tmp_path / 'empty') as bag:
        bag.write_float('/tip_load', 0.0, 4.5)
        bag.add_topic('/tip_pose', 'geometry_msgs/msg/PoseStamped')
    assert main(['analyze', str(tmp_path / 'empty')]) == 2
    assert '/tip_pose holds no messages' in _error_line(capsys)
    short = _bag(tmp_path / 'short', poses=[(i / 180, -0.03) for i in range(20)])
    assert main(['analyze', str(short)]) == 2
    assert '20 valid pose samples, need at least 50' in _error_line(capsys)


@pytest.mark.parametrize('fraction', [0.5, 0.8])
def test_truncated_bag_is_one_line_or_a_kept_partial_result(drop_bag, tmp_path, capsys, fraction):
    cut = tmp_path / 'cut'
    shutil.copytree(drop_bag, cut)
    data = next(cut.glob('*.mcap'))
    data.write_bytes(data.read_bytes()[: int(data.stat().st_size * fraction)])
    out = tmp_path / 'r.json'
    code = main(['analyze', str(cut), '--json', str(out)])
    captured = capsys.readouterr()
    # What survives depends on where the cut falls among the writer's chunks.
    if code == 2:
        last = captured.err.strip().splitlines()[-1]
        assert last.startswith('lumpbeam analyze: error: ') and '/tip_pose' in last
        assert 'Traceback' not in captured.err
    else:
        assert code in (0, 1) and 'status: ' in captured.out
        result = json.loads(out.read_text())
        assert 0 < result['n_samples'] < 2161 and result['window_end_s'] < 12.0


def test_no_oscillation_keeps_partial_results(tmp_path, capsys):
    bag = _bag(tmp_path / 'b', poses=[(i / 180, -0.03) for i in range(500)])
    out = tmp_path / 'r.json'
    assert main(['analyze', str(bag), '--json', str(out)]) == 1
    assert 'status: ERROR no oscillation' in capsys.readouterr().out
    data = json.loads(out.read_text())
    assert data['status'] == 'ERROR' and data['natural_frequency_hz'] is None
    assert data['n_samples'] == 500


def test_bad_identifier_config_is_one_line(drop_bag, tmp_path, capsys):
    bad = tmp_path / 'ident.yaml'
    bad.write_text('/**:\n  ros__parameters:\n    fit:\n      max_modes: 9\n')
    assert main(['analyze', str(drop_bag), '--identifier-config', str(bad)]) == 2
    assert 'fit.max_modes: must be in [1, 8], got 9' in _error_line(capsys)


def _warnings(err):
    return [line for line in err.splitlines() if line.startswith('lumpbeam analyze: warning: ')]


def _check_estimates(out, release_s=2.0, status='OK'):
    data = json.loads(out.read_text())
    truth = chain_modes(LumpedChain.from_beam(BeamParameters(), 0.0)).natural_frequency_hz[0]
    assert data['status'] == status
    assert abs(data['natural_frequency_hz'] - truth) < 3 * data['natural_frequency_hz_std']
    assert data['release_time_s'] == pytest.approx(release_s, abs=1.0 / 180.0)
    return data


def test_a_nan_orientation_drops_that_pose_and_says_so(drop_bag, tmp_path, capsys):
    def nan_pitch(rows):
        rows[1000][3] = math.nan
        return rows

    bag = rewritten(drop_bag, tmp_path / 'nan', nan_pitch)
    out = tmp_path / 'r.json'
    assert main(['analyze', str(bag), '--json', str(out)]) == 0
    warnings = _warnings(capsys.readouterr().err)
    assert len(warnings) == 1 and '/tip_pose: dropped 1 of 2161 poses' in warnings[0]
    assert 'NaN or inf' in warnings[0]
    assert _check_estimates(out)['n_rejected'] == 1


def test_duplicate_and_out_of_order_stamps_are_named(drop_bag, tmp_path, capsys):
    def shuffle(rows):
        rows[500], rows[501] = rows[501], rows[500]
        return rows + [list(rows[700]), list(rows[701])]

    bag = rewritten(drop_bag, tmp_path / 'dup', shuffle)
    out = tmp_path / 'r.json'
    assert main(['analyze', str(bag), '--json', str(out)]) == 0
    warnings = _warnings(capsys.readouterr().err)
    assert len(warnings) == 1 and (
        'dropped 2 of 2163 poses (2 with a repeated or out-of-order stamp)' in warnings[0]
    ), warnings
    _check_estimates(out)


@pytest.mark.parametrize('jump_s', [100.0, 1e6])
@pytest.mark.parametrize('at_s', [1.0, 9.0], ids=['before_release', 'after_release'])
def test_a_jump_in_the_stamps_keeps_the_release_segment(drop_bag, tmp_path, capsys, jump_s, at_s):
    def jump(rows):
        for row in rows:
            if row[0] > at_s:
                row[0] += jump_s
        return rows

    bag = rewritten(drop_bag, tmp_path / 'jump', jump)
    out = tmp_path / 'r.json'
    code = main(['analyze', str(bag), '--json', str(out)])
    captured = capsys.readouterr()
    assert 'Traceback' not in captured.err and 'overflow' not in captured.err
    warnings = _warnings(captured.err)
    assert len(warnings) == 1 and f'stamps jump by {jump_s:+.3g}' in warnings[0], warnings
    assert 'the release)' in warnings[0]
    if at_s == 9.0:
        assert code == 0 and 'kept 0.000 to 9.000 s (1621 poses' in warnings[0]
        _check_estimates(out)
    else:
        # The kept stretch holds the release and a quiet second before it; the /tip_load
        # drop (its stamps did not jump) is 100 s or more away from it, which is named.
        assert code == 0
        data = _check_estimates(out, 2.0 + jump_s, 'WARN')
        assert data['message'].startswith('/tip_load ')


@pytest.mark.parametrize(
    ('value', 'problem'),
    [
        ('0', 'must be in [1, 8], got 0'),
        ('-2', 'must be in [1, 8], got -2'),
        ('1000000', 'must be in [1, 8], got 1000000'),
        ('1.5', "must be an integer, got '1.5'"),
        ('many', "must be an integer, got 'many'"),
    ],
)
def test_bad_max_modes_is_one_line(drop_bag, capsys, value, problem):
    assert main(['analyze', str(drop_bag), f'--max-modes={value}']) == 2
    assert _error_line(capsys) == f'lumpbeam analyze: error: --max-modes: {problem}'


@pytest.fixture(scope='module')
def arm_bag(tmp_path_factory):
    return write_bag(tmp_path_factory.mktemp('arm') / 'rotary', ring_down())


def test_an_arm_bag_gives_the_modes_after_the_last_move(arm_bag, tmp_path, capsys):
    out = tmp_path / 'arm.json'
    arm = str(config_path('arm_rotary.yaml'))
    assert main(['analyze', str(arm_bag), '--arm', arm, '--json', str(out)]) == 0
    text = capsys.readouterr().out
    assert 'joints at rest from 0.300 s at q = 0.5 rad' in text
    assert '(arm model: 3.478 Hz' in text  # the rotary arm file's first mode at q = 0.5
    data = json.loads(out.read_text())
    assert data['release_source'] == 'joint_states' and data['joint_angles_rad'] == [0.5]
    assert data['stiffness_total_nm_per_rad'] is None  # no load left: B.12 does not apply
    assert [list(mode) for mode in data['modes']] == [
        [
            'natural_frequency_hz',
            'natural_frequency_hz_std',
            'damping_ratio',
            'damping_ratio_std',
            'amplitude_m',
        ]
    ] * len(MODES)
    for mode, (f, zeta, amplitude) in zip(data['modes'], MODES, strict=True):
        assert abs(mode['natural_frequency_hz'] - f) < 4 * mode['natural_frequency_hz_std']
        assert abs(mode['damping_ratio'] - zeta) < 4 * mode['damping_ratio_std']
        assert mode['amplitude_m'] == pytest.approx(amplitude, rel=0.1)
    assert data['natural_frequency_hz'] == data['modes'][0]['natural_frequency_hz']
    # At most one mode when asked.
    assert (
        main(['analyze', str(arm_bag), '--arm', arm, '--max-modes', '1', '--json', str(out)]) == 0
    )
    assert len(json.loads(out.read_text())['modes']) == 1


def test_an_arm_bag_with_other_joints_or_no_move_is_one_line(arm_bag, tmp_path, capsys):
    three = str(config_path('arm_3link.yaml'))
    assert main(['analyze', str(arm_bag), '--arm', three]) == 2
    assert '/joint_states has 1 joint(s) (joint_1), the arm 3' in _error_line(capsys)
    still = ring_down(end_rad=0.0)
    bag = write_bag(tmp_path / 'still', still)
    rotary = str(config_path('arm_rotary.yaml'))
    assert main(['analyze', str(bag), '--arm', rotary]) == 2
    assert 'the joints never move' in _error_line(capsys)
    assert main(['analyze', str(_bag(tmp_path / 'b', poses=[(0.0, 0.0)])), '--arm', rotary]) == 2
    assert 'no topic /joint_states (topics: /tip_pose)' in _error_line(capsys)


def test_an_arm_bag_without_arm_says_so(arm_bag, capsys):
    main(['analyze', str(arm_bag)])
    assert 'taken as a drop test, but the bag has /joint_states: an arm? (--arm FILE)' in (
        capsys.readouterr().err
    )


#: A steel cantilever tapped once, an accelerometer at its tip (m/s^2), 1.65 kHz: its three
#: modes and 50 Hz mains hum.
TAPPED = Tap(1650, 12, (1.0,), ((6.62, 0.004, 10.0), (41.4, 0.003, 5.0), (117.5, 0.002, 3.0)),
             noise=0.05, hum=(50.0, 0.2))  # fmt: skip


def _imported(tmp_path, t, y, quantity='acceleration'):
    """A record as a lab has it (CSV), through ``lumpbeam import``."""
    csv = tmp_path / 'record.csv'
    csv.write_text(
        'time,signal\n'
        + ''.join(f'{float(a)!r},{float(b)!r}\n' for a, b in zip(t, y, strict=True))
    )
    bag = tmp_path / 'bag'
    args = ['import', str(csv), str(bag), '--quantity', quantity, '--column', 'signal']
    assert main([*args, '--time-column', 'time']) == 0
    return bag


def test_an_accelerometer_record_of_a_tap_gives_its_modes_events_and_lines(tmp_path, capsys):
    bag = _imported(tmp_path, *TAPPED.record())
    out = tmp_path / 'r.json'
    assert main(['analyze', str(bag), '--json', str(out)]) == 0
    printed = capsys.readouterr().out
    assert 'accelerations (/tip_imu)' in printed and 'steady line 49.99' in printed
    data = json.loads(out.read_text())
    [event] = data['events']
    # Stamped from lumpbeam import's default start, 2000-01-01T00:00:00Z.
    assert event['kind'] == 'impact' and 1.0 <= event['start_s'] - 946684800.0 < 1.2
    assert data['modes'] == event['modes'] and len(data['modes']) == 3
    for mode, (f, zeta, _) in zip(data['modes'], TAPPED.modes, strict=True):
        assert abs(mode['natural_frequency_hz'] - f) <= 3 * mode['natural_frequency_hz_std']
        assert abs(mode['damping_ratio'] - zeta) <= 3 * mode['damping_ratio_std']
    [line] = data['lines']
    assert line['frequency_hz'] == pytest.approx(50.0, abs=1e-3)
    # No static change of a tip pose: no stiffness.
    assert data['stiffness_total_nm_per_rad'] is None and data['status'] == 'OK'


def test_a_band_restricts_the_modes_looked_for(tmp_path):
    bag = _imported(tmp_path, *TAPPED.record())
    out = tmp_path / 'r.json'
    assert main(['analyze', str(bag), '--json', str(out), '--band', '20,80']) == 0
    [mode] = json.loads(out.read_text())['modes']
    assert mode['natural_frequency_hz'] == pytest.approx(41.4, rel=1e-3)


def test_a_shaker_still_running_gives_lines_and_no_mode(tmp_path, capsys):
    """A measured record (test/data/records): a cantilever driven at 100, 120 and 150 Hz."""
    lvm = Path(__file__).parents[2] / 'data' / 'records' / 'shaker_cantilever_test3_400hz.lvm'
    bag = tmp_path / 'shaker'
    args = ['--quantity', 'acceleration', '--column', 'Acceleration', '--unit', 'g']
    assert main(['import', str(lvm), str(bag), *args]) == 0
    out = tmp_path / 'r.json'
    assert main(['analyze', str(bag), '--json', str(out)]) == 1
    data = json.loads(out.read_text())
    assert data['status'] == 'ERROR' and 'no free vibration' in data['message']
    assert data['natural_frequency_hz'] is None and data['modes'] == data['events'] == []
    lines = sorted(line['frequency_hz'] for line in data['lines'])
    assert lines == pytest.approx([100.0, 120.0, 150.0], abs=0.05)


@pytest.mark.parametrize('band', ['20', '80,20', 'a,b', '-1,5', 'nan,5', '1,2,3'])
def test_a_bad_band_is_one_line(drop_bag, band, capsys):
    assert main(['analyze', str(drop_bag), f'--band={band}']) == 2
    assert f'--band {band!r}: give LOW,HIGH in Hz' in _error_line(capsys)


def test_plots_of_an_accelerometer_record_are_refused_in_one_line(tmp_path, capsys):
    bag = _imported(tmp_path, *TAPPED.record())
    capsys.readouterr()
    assert main(['analyze', str(bag), '--plots', str(tmp_path / 'plots')]) == 2
    assert '--plots draws tip poses' in _error_line(capsys)


RECORDS = Path(__file__).parents[2] / 'data' / 'records'


def _shock(trial, tmp_path):
    """A measured shock of a circuit board (test/data/records), imported and analysed."""
    source = RECORDS / f'pcb_shock_acc_pcb_a{trial}.txt'
    bag, out = tmp_path / f'b{trial}', tmp_path / f'r{trial}.json'
    columns = ['--time-column', 'time(s)', '--column', 'acceleration(g)', '--unit', 'g']
    assert main(['import', str(source), str(bag), '--quantity', 'acceleration', *columns]) == 0
    assert main(['analyze', str(bag), '--json', str(out)]) == 0
    return np.loadtxt(source), json.loads(out.read_text())


def test_measured_shocks_of_one_board_agree_within_their_standard_deviations(tmp_path):
    first = {}
    for trial in (0, 10, 20):
        record, data = _shock(trial, tmp_path)
        [event] = data['events']
        assert event['kind'] == 'impact' and data['status'] == 'OK'
        mode = data['modes'][0]
        # A plain FFT of the whole record puts the board's strongest peak within 0.3 %.
        t, a = record[:, 0], record[:, 1]
        spectrum = np.abs(np.fft.rfft((a - a.mean()) * np.hanning(a.size), 16 * a.size))
        peak = np.fft.rfftfreq(16 * a.size, np.median(np.diff(t)))[np.argmax(spectrum)]
        assert mode['natural_frequency_hz'] == pytest.approx(peak, rel=3e-3)
        for key in ('natural_frequency_hz', 'damping_ratio'):
            if key in first:
                apart = abs(mode[key] - first[key][0])
                assert apart <= 3 * math.hypot(mode[f'{key}_std'], first[key][1]), (trial, key)
            else:
                first[key] = (mode[key], mode[f'{key}_std'])


def _imu_bag(path, values, rate=1000.0):
    with BagWriter(path) as bag:
        for i, a in enumerate(values):
            bag.write_acceleration('/tip_imu', i / rate, (0.0, 0.0, a), 'tip')
    return path


def test_an_accelerometer_bag_too_short_is_one_line(tmp_path, capsys):
    bag = _imu_bag(tmp_path / 'short', [0.1, -0.2, 0.3, math.nan, 0.1])
    assert main(['analyze', str(bag)]) == 2
    assert '/tip_imu holds 4 usable samples' in _error_line(capsys)


def test_non_finite_accelerations_are_dropped_and_said(tmp_path, capsys):
    t, y = TAPPED.record()
    y = y.copy()
    y[::500] = math.nan  # a logger's dropouts
    bag = _imu_bag(tmp_path / 'gaps', y, rate=TAPPED.rate_hz)
    out = tmp_path / 'r.json'
    assert main(['analyze', str(bag), '--json', str(out)]) == 0
    captured = capsys.readouterr()
    assert 'non-finite' in captured.err or 'dropped' in captured.err, captured.err
    data = json.loads(out.read_text())
    assert data['status'] != 'ERROR' and len(data['modes']) == 3
