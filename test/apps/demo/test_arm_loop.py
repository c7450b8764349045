"""``lumpbeam demo --arm``: the input-shaping loop live, and its pieces."""

import json
import math

import numpy as np
import pytest

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.apps.demo import arm_graph, arm_loop
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import IDENTIFIER_STATUS, JOINT_TRAJECTORY_TYPE
from lumpbeam_ros.base.resources import config_path
from lumpbeam_ros.core.bagio import BagReader
from lumpbeam_ros.core.bagio.series import read_diagnostics
from lumpbeam_ros.core.model.arm.config import load_arm_config
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.statics import arm_modes, modes_table


def test_the_moves_go_out_and_back_from_rest():
    arm = load_arm_config(config_path('arm_3link.yaml'))
    out, back = arm_loop.the_moves(arm)
    for move, start, end in ((out, 0.0, arm_loop.MOVE_RAD), (back, arm_loop.MOVE_RAD, 0.0)):
        assert move.joint_names == ('joint_1', 'joint_2', 'joint_3')
        assert move.time_s[-1] == pytest.approx(arm_graph.HOLD_S + arm_loop.MOVE_S)
        assert move.angles_rad[0, 0] == move.angles_rad[1, 0] == start  # held, then moves
        assert move.angles_rad[-1, 0] == end
        assert not move.angles_rad[:, 1:].any()  # the other joints stay at 0
        # Minimum jerk: at rest at both ends, no faster than 15/8 of the mean rate.
        speed = np.diff(move.angles_rad[1:, 0]) / np.diff(move.time_s[1:])
        assert abs(speed[0]) < 1e-3 and abs(speed[-1]) < 1e-3
        assert np.abs(speed).max() == pytest.approx(
            1.875 * arm_loop.MOVE_RAD / arm_loop.MOVE_S, 1e-3
        )


def _status(frequency_hz, damping_ratio, **more):
    values = {
        'natural_frequency_hz': repr(frequency_hz),
        'natural_frequency_hz_std': repr(frequency_hz * 1e-3),
        'damping_ratio': repr(damping_ratio),
        'damping_ratio_std': repr(damping_ratio * 0.01),
    }
    values.update(more)
    return values


def test_settle_time_is_the_slowest_modes_decay_to_two_percent():
    # exp(-zeta omega t) = 0.02 for zeta = 0.02 at 3.5 Hz: t = ln 50 / (0.02 x 2 pi x 3.5).
    expected = math.log(50.0) / (0.02 * 2 * math.pi * 3.5)
    assert arm_loop.settle_time(_status(3.5, 0.02)) == pytest.approx(expected)
    # A faster-decaying second mode does not shorten it; a slower one sets it.
    fast = {'mode_count': '2', 'mode_2_natural_frequency_hz': '20.0'}
    fast |= {'mode_2_natural_frequency_hz_std': '0.1', 'mode_2_damping_ratio': '0.1'}
    fast |= {'mode_2_damping_ratio_std': '0.01'}
    assert arm_loop.settle_time(_status(3.5, 0.02, **fast)) == pytest.approx(expected)
    slow = dict(fast, mode_2_damping_ratio='0.001', mode_2_damping_ratio_std='0.0001')
    assert arm_loop.settle_time(_status(3.5, 0.02, **slow)) == pytest.approx(
        math.log(50.0) / (0.001 * 2 * math.pi * 20.0)
    )


def test_settle_time_refuses_an_undamped_or_invalid_estimate():
    with pytest.raises(LumpbeamError, match='undamped'):
        arm_loop.settle_time(_status(3.5, 0.0))
    with pytest.raises(LumpbeamError, match='damping_ratio missing'):
        arm_loop.settle_time({'natural_frequency_hz': '3.5', 'natural_frequency_hz_std': '0.1'})


# About a minute: the whole graph (five processes) through two moves and a 9 s ring-down.
@pytest.mark.slow
@pytest.mark.ros
def test_arm_demo_shapes_the_second_move_live(tmp_path, capsys):
    out = tmp_path / 'results'
    code = main(['demo', '--arm', '--out', str(out), '--json', str(tmp_path / 's.json')])
    printed = capsys.readouterr().out
    assert code == 0, printed
    summary = json.loads((tmp_path / 's.json').read_text())
    assert summary == json.loads((out / 'summary.json').read_text())
    # The shaped move rings at least 90 % less, as printed.
    assert summary['reduction'] >= 0.9
    assert summary['residual_shaped_m'] < 0.1 * summary['residual_unshaped_m']
    assert 'residual vibration: unshaped' in printed and '% less' in printed
    assert 'shaper node: shaping with ZV for' in printed
    assert summary['shaped_duration_added_s'] > 0.0
    # What the identifier found live is the arm's first mode as its linearized model gives
    # it (the eigenvalues at the move's end, not a fit of the ring-down).
    arm = load_arm_config(config_path('arm_rotary.yaml'))
    truth = modes_table(arm_modes(ArmModel.from_config(arm), np.array([arm_loop.MOVE_RAD])))
    identified = float(summary['identified']['natural_frequency_hz'])
    assert identified == pytest.approx(truth[0]['natural_frequency_hz'], rel=5e-3)
    # The bag holds the whole loop.
    bag = out / 'bags' / 'recorded'
    counts = {name: entry.count for name, entry in BagReader(bag).topics.items()}
    assert counts['/joint_trajectory'] == counts['/joint_trajectory_shaped'] == 2
    for topic in ('/joint_states', '/tip_pose', '/tip_pose_truth', '/tip_pose_predicted'):
        assert counts[topic] > 10 * 180, topic
    statuses = [
        s for _, array in read_diagnostics(bag) for s in array if s.name == IDENTIFIER_STATUS
    ]
    assert any(s.level == 0 and 'mode_count' in s.values for s in statuses)
    shaped = [
        msg
        for _, msg in BagReader(bag).messages('/joint_trajectory_shaped', JOINT_TRAJECTORY_TYPE)
    ]
    ends = [m.points[-1].time_from_start for m in shaped]
    assert ends[1].sec + ends[1].nanosec * 1e-9 > ends[0].sec + ends[0].nanosec * 1e-9
    figure = out / 'figures' / arm_loop.FIGURE_NAME
    assert figure.stat().st_size > 10_000 and str(figure) == summary['figure']
