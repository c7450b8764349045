import json
import math
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from arm_cases import small_arm, write_move_bag
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import PoseStamped
from harness import ros_env
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from ring_downs import MODES, ring_down
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64

from lumpbeam_ros.apps.cli.analyze import read_window
from lumpbeam_ros.base.errors import ConfigError, LumpbeamError
from lumpbeam_ros.base.interface import ARM_PARAMS, ARM_STATUS
from lumpbeam_ros.base.interface import IDENTIFIER_STATUS as STATUS_NAME
from lumpbeam_ros.base.resources import config_path
from lumpbeam_ros.core.bagio import read_tip_poses
from lumpbeam_ros.core.bagio.convert import pitch_to_quaternion
from lumpbeam_ros.core.bagio.series import read_joint_states
from lumpbeam_ros.core.ident.arm.learner import ArmEstimate
from lumpbeam_ros.core.ident.arm.link_fit import link_stiffness_total, scaled_arm
from lumpbeam_ros.core.ident.bag_analysis import analyze_bag
from lumpbeam_ros.core.ident.identification import Status
from lumpbeam_ros.core.ident.identify import identify
from lumpbeam_ros.core.ident.settings import IdentifierConfig
from lumpbeam_ros.core.model import rules
from lumpbeam_ros.core.model.arm.config import write_arm_config
from lumpbeam_ros.core.model.chain import LumpedChain
from lumpbeam_ros.core.model.modes import chain_modes
from lumpbeam_ros.core.model.parameters import BeamParameters, DropTestConfig
from lumpbeam_ros.core.model.statics import static_tip_deflection
from lumpbeam_ros.core.shaping.estimate import estimate_from_status
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, write_drop_test_bag
from lumpbeam_ros.nodes.identifier_node import IdentifierNode
from lumpbeam_ros.nodes.lifecycle import live_spinner, spin_events
from lumpbeam_ros.nodes.msgtypes import topic_qos

ROOT = Path(__file__).resolve().parents[2]


def _statuses(messages):
    out = []
    for msg in messages:
        assert len(msg.status) == 1
        status = msg.status[0]
        assert status.name == STATUS_NAME and status.hardware_id == 'beam'
        out.append((status.level[0], status.message, {kv.key: kv.value for kv in status.values}))
    return out


# A release between two frames, so the test can tell a fitted onset from a frame stamp.
RELEASE_S = 2.0 + 0.37 / 180.0
FRAME_S = 1.0 / 180.0
#: When /tip_load says the load left, relative to the release, s (None: it never does).
ARRIVALS = {'late_100ms': 0.1, 'late_300ms': 0.3, 'early_100ms': -0.1, 'no_tip_load': None}
#: Replay speed against the bag's clock; inf: each message as soon as the node took the last.
RATES = {'rate_0.5': 0.5, 'rate_1': 1.0, 'fastest': math.inf}
ESTIMATES = ('natural_frequency_hz', 'damping_ratio', 'stiffness_total_nm_per_rad')


@pytest.fixture(scope='module')
def drop_record(tmp_path_factory):
    """The synthetic drop test (release between frames), its analyze result and the truth."""
    bag = tmp_path_factory.mktemp('identifier') / 'drop'
    drop = DropTestConfig(release_time_s=RELEASE_S)
    write_drop_test_bag(bag, BeamParameters(), drop, SynthOptions(duration_s=11.5))
    poses = read_tip_poses(bag, '/tip_pose')
    batch = identify(read_window(bag), BeamParameters(), IdentifierConfig(max_fit_s=math.inf))
    return poses, batch, _truth(BeamParameters(), drop)


def _truth(beam, drop):
    """f_n and zeta of the unloaded chain; k_tE by B.12 from the model's two equilibria."""
    modes = chain_modes(LumpedChain.from_beam(beam, 0.0))
    deflection = static_tip_deflection(beam, drop.load_kg) - static_tip_deflection(beam, 0.0)
    force = drop.load_kg * beam.gravity_mps2
    return {
        'natural_frequency_hz': float(modes.natural_frequency_hz[0]),
        'damping_ratio': float(modes.damping_ratio[0]),
        'stiffness_total_nm_per_rad': rules.total_stiffness_from_deflection(
            force, beam.length_m, deflection
        ),
    }


def _replay(ros_graph, node, poses, arrival, rate):
    """Plays the poses with /clock and /tip_load (4.5 kg, then 0 kg at the release + arrival).

    Each message waits for the node to have taken the one before (no queue can overflow, so
    the node sees every pose whatever the machine's load); at a finite rate it is also held
    back to its time on the bag's clock. After the last pose /clock runs on until the node
    has published an update of the whole window.

    Returns:
        The statuses published.
    """
    params = ros_graph.collect('/beam_params', DiagnosticArray, 100)
    latched = QoSProfile(
        depth=1,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )
    clock = Clock()

    def tick(stamp):
        clock.clock.sec, clock.clock.nanosec = divmod(int(round(stamp * 1e9)), 1_000_000_000)
        ros_graph.publish('/clock', clock, qos=100)

    def load(kg):
        ros_graph.publish('/tip_load', Float64(data=kg), qos=latched)
        taken = lambda: node.window.snapshot().loads.kg[-1:].tolist() == [kg]  # noqa: E731
        assert ros_graph.spin_until(taken, 30.0)

    tick(float(poses.t[0]))
    ros_graph.publish('/tip_pose', _pose(-1.0, float(poses.z[0])), qos=1000)
    topics = ['/clock', '/tip_pose']
    if arrival is not None:
        load(4.5)
        topics.append('/tip_load')
    for topic in topics:
        assert ros_graph.wait_for_subscribers(topic, timeout=30.0)
    pending = None if arrival is None else RELEASE_S + arrival
    started = time.monotonic()
    for t, x, z, pitch in zip(poses.t, poses.x, poses.z, poses.pitch, strict=True):
        if math.isfinite(rate):
            due = started + (t - poses.t[0]) / rate
            ros_graph.spin_until(lambda due=due: time.monotonic() >= due, 60.0)
        tick(float(t))
        if pending is not None and t >= pending:
            load(0.0)
            pending = None
        ros_graph.publish('/tip_pose', _pose(float(t), float(z), pitch=float(pitch), x=x))
        assert ros_graph.spin_until(lambda t=t: node.window.newest_s >= t, 30.0)
    last = float(poses.t[-1])

    def whole_window_published():
        statuses = _statuses(params)
        return bool(statuses) and float(statuses[-1][2]['window_end_s']) == last

    for k in range(1, 100):
        tick(last + 0.05 * k)
        if ros_graph.spin_until(whole_window_published, 1.0):
            break
    assert whole_window_published()
    return _statuses(params)


def _check_replay(statuses, batch, truth, arrival):
    """The last update: OK, release within a frame, estimates within the batch's tolerances.

    Returns:
        The release error in frames, and each estimate's (value - truth) / analyze's std.
    """
    level, message, last = statuses[-1]
    assert level == 0, message
    release_error = float(last['release_time_s']) - RELEASE_S
    assert abs(release_error) < FRAME_S, release_error
    assert last['release_source'] == ('data' if arrival is None else 'tip_load')
    errors = {}
    for key in ESTIMATES:
        value = float(last[key])
        errors[key] = (value - truth[key]) / batch.figure(key).std
        # lumpbeam analyze's own std on the whole record is the tolerance.
        assert abs(errors[key]) < 3.0, (key, value, truth[key])
    return release_error / FRAME_S, errors


def _identifier(ros_graph):
    node = IdentifierNode(
        context=ros_graph.context,
        parameter_overrides={'use_sim_time': True, 'publish_rate_hz': 1.0},
    )
    ros_graph.add_node(node)
    return node


@pytest.mark.parametrize('arrival', ['late_300ms', 'no_tip_load'])
def test_replayed_drop_test_gives_ok_estimates(ros_graph, drop_record, arrival):
    poses, batch, truth = drop_record
    node = _identifier(ros_graph)
    statuses = _replay(ros_graph, node, poses, ARRIVALS[arrival], math.inf)
    assert sum(level == 0 for level, _, _ in statuses) >= 5  # 1 Hz on the bag's clock
    _check_replay(statuses, batch, truth, ARRIVALS[arrival])
    last = statuses[-1][2]
    # doc/interfaces.md, 'Topics': every float is a repr, every key has its std.
    for key in ESTIMATES:
        assert repr(float(last[key])) == last[key] and float(last[f'{key}_std']) > 0
    for key in ('window_start_s', 'window_end_s', 'cycles', 'method', 'release_time_s_std'):
        assert key in last
    assert float(last['window_end_s']) <= 11.5 and last['samples_wrong_frame'] == '0'


@pytest.mark.slow
@pytest.mark.ros
@pytest.mark.parametrize('rate', list(RATES))
@pytest.mark.parametrize('arrival', list(ARRIVALS))
def test_release_matrix_of_arrivals_and_rates(ros_graph, drop_record, arrival, rate):
    """Every /tip_load arrival at every replay rate; each prints its row (-s -m slow)."""
    poses, batch, truth = drop_record
    node = _identifier(ros_graph)
    statuses = _replay(ros_graph, node, poses, ARRIVALS[arrival], RATES[rate])
    frames, errors = _check_replay(statuses, batch, truth, ARRIVALS[arrival])
    sigmas = ' '.join(f'{errors[key]:+6.2f}' for key in ESTIMATES)
    print(f'\nRELEASE_MATRIX {arrival:<12} {rate:<8} release {frames:+.3f} frames; ' + sigmas)


def _pose(stamp, z, frame='beam_base', pitch_w=1.0, pitch=0.0, x=2.3):
    msg = PoseStamped()
    msg.header.frame_id = frame
    msg.header.stamp.sec, nanosec = divmod(int(round(stamp * 1e9)), 1_000_000_000)
    msg.header.stamp.nanosec = nanosec
    msg.pose.position.x, msg.pose.position.z = float(x), z
    q = msg.pose.orientation
    q.x, q.y, q.z, q.w = pitch_to_quaternion(pitch)
    if pitch_w != 1.0:
        q.w = pitch_w
    return msg


def test_the_window_carries_the_tip_x_of_the_poses(ros_graph):
    node = IdentifierNode(context=ros_graph.context)
    ros_graph.add_node(node)
    ros_graph.publish('/tip_pose', _pose(10.0, -0.01, x=2.25), qos=100)
    assert ros_graph.wait_for_subscribers('/tip_pose')
    for i in range(1, 4):
        ros_graph.publish('/tip_pose', _pose(10.0 + i / 100, -0.01, x=2.25 + i / 1000))
    assert ros_graph.spin_until(lambda: node.window.newest_s >= 10.03, 10.0)
    poses = node.window.snapshot().poses
    np.testing.assert_allclose(poses.x[-3:], [2.251, 2.252, 2.253])


def test_bad_input_gives_errors_not_crashes_or_garbage(ros_graph):
    node = IdentifierNode(context=ros_graph.context, parameter_overrides={'publish_rate_hz': 20.0})
    ros_graph.add_node(node)
    params = ros_graph.collect('/beam_params', DiagnosticArray, 100)
    ros_graph.publish('/tip_pose', _pose(0.0, 0.0), qos=1000)
    ros_graph.wait_for_subscribers('/tip_pose')
    bad = []
    for i in range(200):
        t = 100.0 + i / 180.0
        bad += [
            _pose(t, math.nan),  # NaN
            _pose(t + 1e-4, -0.01, frame='camera'),  # wrong frame
            _pose(t + 2e-4, -0.01, pitch_w=math.inf),  # broken orientation
        ]
    bad += [_pose(200.0 - i, 0.0) for i in range(60)]  # time running backwards
    for msg in bad:
        ros_graph.publish('/tip_pose', msg)
        ros_graph.executor.spin_once(timeout_sec=0.0)
    # Reliable with deep queues, but a burst may outrun the subscriber's queue: wait until
    # the published counts show each kind of bad input arrived, rather than all of it.

    def seen_all():
        if not params:
            return False
        values = _statuses(params[-1:])[0][2]
        return (
            int(values['samples_wrong_frame']) >= 100
            and int(values['samples_non_finite']) >= 200
            and int(values['window_resets']) >= 1
        )

    assert ros_graph.spin_until(seen_all, 10.0)
    statuses = _statuses(params)
    assert {level for level, _, _ in statuses} == {2}
    assert all(math.isnan(float(values['natural_frequency_hz'])) for _, _, values in statuses)
    assert int(statuses[-1][2]['samples_wrong_frame']) == node.wrong_frame
    # The status message says what was dropped, not only the counts.
    non_finite = int(statuses[-1][2]['samples_non_finite'])
    assert '/tip_pose: dropped ' in statuses[-1][1]
    assert f'({non_finite} with a NaN or inf stamp, position or orientation; ' in statuses[-1][1]
    assert 'with a repeated or out-of-order stamp)' in statuses[-1][1]


def test_parameters_are_validated():
    import rclpy
    from rclpy.context import Context

    context = Context()
    rclpy.init(context=context, domain_id=0)
    try:
        for overrides, problem in [
            ({'window.length_s': -1.0}, 'window.length_s: must be positive'),
            ({'fit.max_modes': 9}, 'fit.max_modes'),
            ({'fit.nonlinear': 'maybe'}, 'fit.nonlinear'),
            ({'beam_config': '/nonexistent.yaml'}, 'nonexistent'),
        ]:
            with pytest.raises(LumpbeamError, match=problem):
                IdentifierNode(context=context, parameter_overrides=overrides)
        node = IdentifierNode(context=context, parameter_overrides={'fit.max_modes': 1})
        assert node.config.max_modes == 1
        described = node.describe_parameters(['fit.nonlinear', 'effective_mass.beam_fraction'])
        assert 'squared amplitude' in described[0].description
        assert described[0].additional_constraints == 'one of auto, always, never'
        assert described[1].floating_point_range[0].to_value == 1.0
        node.destroy_node()
    finally:
        rclpy.shutdown(context=context)


@pytest.mark.parametrize('sim_time', [False, True], ids=['wall time', 'use_sim_time'])
def test_a_live_node_spins_on_the_events_executor_and_a_replay_on_rclpys(ros_graph, sim_time):
    import rclpy

    node = IdentifierNode(
        context=ros_graph.context, parameter_overrides={'use_sim_time': sim_time}
    )
    try:
        # On /clock, rclpy's own executor: its timers follow a simulated clock in every release.
        assert live_spinner(node) is (rclpy.spin if sim_time else spin_events)
    finally:
        node.destroy_node()


def test_main_takes_the_params_file_and_rejects_a_bad_one(ros_graph, tmp_path):
    env = ros_env(ros_graph.domain_id)
    env['PYTHONPATH'] = str(ROOT)
    command = [sys.executable, '-m', 'lumpbeam_ros.nodes.identifier_node', '--ros-args']
    params = ros_graph.collect('/beam_params', DiagnosticArray, 10)
    good = [*command, '--params-file', str(config_path('identifier.yaml'))]
    process = subprocess.Popen([*good, '-p', 'publish_rate_hz:=10.0'], env=env)
    try:
        assert ros_graph.spin_until(lambda: len(params) >= 2, 60.0)
    finally:
        process.terminate()
        process.wait(10)
    assert _statuses(params)[-1][0] == 2  # no poses: no estimate
    bad = tmp_path / 'bad.yaml'
    bad.write_text('/**:\n  ros__parameters:\n    window:\n      length_s: -3.0\n')
    run = subprocess.run(
        [*command, '--params-file', str(bad)], env=env, capture_output=True, text=True, timeout=30
    )
    assert run.returncode == 2
    assert run.stderr.strip().splitlines()[-1].startswith('identifier_node: ')
    assert 'window.length_s: must be positive' in run.stderr


def test_beam_params_keep_the_keys_their_order_and_values(ros_graph, tmp_path):
    """The /beam_params pairs of the default drop test, as before the result was nested."""
    golden = json.loads((ROOT / 'test' / 'data' / 'analyze_drop_golden.json').read_text())
    bag = tmp_path / 'drop'
    write_drop_test_bag(bag, BeamParameters(), DropTestConfig(), SynthOptions())
    result = analyze_bag(bag, BeamParameters(), IdentifierConfig(), show_progress=False).result
    node = IdentifierNode(context=ros_graph.context)
    ros_graph.add_node(node)
    status = node.diagnostics(result).status[0]
    pairs = [(kv.key, kv.value) for kv in status.values]
    counts = ['samples_wrong_frame', 'samples_non_finite', 'samples_out_of_order', 'window_resets']
    counts.append('joint_states_ignored')
    # The modes came later, after the golden keys: one mode, the top-level one.
    modes = [('mode_count', '1')]
    expected = [*map(tuple, golden['beam_params']), *modes, *((key, '0') for key in counts)]
    assert [key for key, _ in pairs] == [key for key, _ in expected]
    # 1e-6 relative, as analyze's golden test: the stds lose digits to cancellation that
    # another numpy or CPU rounds differently.
    differ = [
        key
        for (key, value), (_, want) in zip(pairs, expected, strict=True)
        if value != want and float(value) != pytest.approx(float(want), rel=1e-6, nan_ok=True)
    ]
    assert differ == []
    assert status.level == bytes([0]) and status.message == result.message


def test_two_replays_feeding_the_node_are_never_ok(ros_graph, drop_record):
    """A bag and another one 0.5 s behind with its own (double) load: WARN, never OK.

    The callbacks are called as the executor would, in order, so no message is lost.
    """
    poses, _, truth = drop_record
    node = IdentifierNode(context=ros_graph.context, parameter_overrides={'publish_rate_hz': 1.0})
    ros_graph.add_node(node)
    params = ros_graph.collect('/beam_params', DiagnosticArray, 10)
    node._on_pose(_pose(float(poses.t[0]), float(poses.z[0])))
    node._on_load(Float64(data=4.5))
    node._on_load(Float64(data=9.0))  # the other bag's load arrives after this one's
    released = False
    for t, x, z, pitch in zip(poses.t[1:], poses.x[1:], poses.z[1:], poses.pitch[1:], strict=True):
        if t >= RELEASE_S + 0.1 and not released:
            node._on_load(Float64(data=0.0))
            released = True
        node._on_pose(_pose(float(t), float(z), pitch=float(pitch), x=x))
        node._on_pose(_pose(float(t) - 0.5, float(z), pitch=float(pitch), x=x))
    node._on_timer()
    assert ros_graph.spin_until(lambda: bool(params), 10.0)
    level, message, values = _statuses(params)[-1]
    k = float(values['stiffness_total_nm_per_rad'])
    assert k == pytest.approx(2.0 * truth['stiffness_total_nm_per_rad'], rel=0.05)  # wrong
    assert level == 1, message  # and said to be
    assert 'the poses may mix two streams' in message
    assert int(values['samples_out_of_order']) == len(poses) - 1
    assert float(values['n_rejected']) > 0.4 * float(values['n_samples'])


def _joint_state(stamp, angles):
    msg = JointState()
    msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(int(round(stamp * 1e9)), 10**9)
    msg.name = [f'joint_{i + 1}' for i in range(len(angles))]
    msg.position = [float(a) for a in angles]
    return msg


def test_an_arm_ring_down_gives_every_mode_on_beam_params(ros_graph):
    """Each move's ring-down from /joint_states; the shaper reads back exactly those keys."""
    record = ring_down()
    node = IdentifierNode(context=ros_graph.context, parameter_overrides={'publish_rate_hz': 1.0})
    ros_graph.add_node(node)
    params = ros_graph.collect('/beam_params', DiagnosticArray, 10)
    moving = record.t < 0.2
    for t, q, x, z in zip(record.t, record.q, record.x, record.z, strict=True):
        node._on_joint_state(_joint_state(float(t), q))
        node._on_pose(_pose(float(t), float(z), x=float(x)))
        if t == record.t[moving][-1]:
            node._on_timer()  # still moving: no ring-down yet
    node._on_joint_state(_joint_state(7.0, [math.nan]))  # ignored and counted
    node._on_timer()
    assert ros_graph.spin_until(lambda: len(params) >= 2, 10.0)
    (first_level, first_message, _), (level, message, values) = _statuses(params)[:2]
    assert first_level == 2 and 'the joints have not stopped after a move' in first_message
    assert level == 0, message
    assert values['release_source'] == 'joint_states' and values['joint_states_ignored'] == '1'
    assert values['mode_count'] == str(len(MODES))
    for k, (f, zeta, _) in enumerate(MODES, start=1):
        prefix = '' if k == 1 else f'mode_{k}_'
        found = float(values[f'{prefix}natural_frequency_hz'])
        assert abs(found - f) < 4 * float(values[f'{prefix}natural_frequency_hz_std'])
        found = float(values[f'{prefix}damping_ratio'])
        assert abs(found - zeta) < 4 * float(values[f'{prefix}damping_ratio_std'])
    shaped = estimate_from_status(level, values, max_modes=3)
    assert [m.mode.frequency_hz for m in shaped.modes] == [
        float(values['natural_frequency_hz']),
        float(values['mode_2_natural_frequency_hz']),
    ]


@pytest.mark.parametrize('value', [-1, 100, 'high'])
def test_a_realtime_priority_out_of_range_stops_the_node_in_one_line(ros_graph, value):
    with pytest.raises(ConfigError, match='realtime_priority: must be') as caught:
        IdentifierNode(context=ros_graph.context, parameter_overrides={'realtime_priority': value})
    assert '\n' not in str(caught.value)


def test_a_realtime_priority_refused_by_the_system_is_a_warning_and_the_node_runs(
    ros_graph, monkeypatch, capfd
):
    import os

    def refuse(*_: object) -> None:
        raise PermissionError(1, 'Operation not permitted')

    # As on a machine without CAP_SYS_NICE (and the test runner stays on its scheduler).
    monkeypatch.setattr(os, 'sched_setscheduler', refuse)
    node = IdentifierNode(context=ros_graph.context, parameter_overrides={'realtime_priority': 40})
    try:
        assert node.updates == 0 and node.window is not None
    finally:
        node.destroy_node()
    assert 'realtime_priority 40: not permitted' in capfd.readouterr().err


def test_an_arm_file_makes_the_node_fit_the_links_after_each_ring_down(ros_graph, tmp_path):
    """/arm_params: the link fitted to a ring-down, from an arm file 20 % off, latched."""
    truth = small_arm(1)
    bag = write_move_bag(tmp_path / 'bag', truth, [0.5], record_s=6.0)
    nominal = scaled_arm(truth, np.array([0.8]), np.array([1.3e-3]))
    arm_file = tmp_path / 'nominal.yaml'
    write_arm_config(arm_file, nominal)
    overrides = {'publish_rate_hz': 1.0, 'arm_config': str(arm_file), 'arm_fit_after_s': 4.0}
    node = IdentifierNode(context=ros_graph.context, parameter_overrides=overrides)
    ros_graph.add_node(node)
    arm_params = ros_graph.collect(ARM_PARAMS, DiagnosticArray, topic_qos(ARM_PARAMS))
    joints, poses = read_joint_states(bag), read_tip_poses(bag)
    for t, q, x, z in zip(poses.t, joints.angles, poses.x, poses.z, strict=True):
        node._on_joint_state(_joint_state(float(t), q))
        node._on_pose(_pose(float(t), float(z), x=float(x)))
        if abs(t - round(t)) < 1e-6:
            node._on_timer()  # once a second, as the timer would
    node._on_timer()
    assert ros_graph.spin_until(lambda: bool(arm_params), 10.0)
    # One fit: the ring-down was taken once, after it had lasted 4 s.
    (status,) = [s for msg in arm_params for s in msg.status]
    assert status.name == ARM_STATUS and status.level == b'\x00', status.message
    values = {kv.key: kv.value for kv in status.values}
    assert values['ring_downs'] == '1' and node.arm_updates == 1
    k, k_std = (
        float(values['link_1_k_total_nm_per_rad']),
        float(values['link_1_k_total_nm_per_rad_std']),
    )
    want = link_stiffness_total(truth.links[0])
    assert abs(k - want) < max(4 * k_std, 1e-3 * want) and k_std < 0.01 * want
    assert float(values['link_1_damping_beta']) == pytest.approx(
        truth.links[0].damping_beta, rel=0.1
    )


def test_a_bad_arm_file_stops_the_node_in_one_line(ros_graph, tmp_path):
    with pytest.raises(ConfigError, match='missing.yaml') as caught:
        IdentifierNode(
            context=ros_graph.context,
            parameter_overrides={'arm_config': str(tmp_path / 'missing.yaml')},
        )
    assert '\n' not in str(caught.value)


def test_arm_fits_undetermined_then_determined_are_both_published(ros_graph, tmp_path):
    # A WARN fit then an OK one (two ring-downs of a two-link arm): rclpy refuses a call site
    # that changes severity, which once stopped the node at its first OK fit.
    arm_file = tmp_path / 'arm.yaml'
    write_arm_config(arm_file, small_arm(2))
    node = IdentifierNode(
        context=ros_graph.context, parameter_overrides={'arm_config': str(arm_file)}
    )
    ros_graph.add_node(node)
    arm_params = ros_graph.collect(ARM_PARAMS, DiagnosticArray, topic_qos(ARM_PARAMS))
    for count, level in enumerate((Status.WARN, Status.OK, Status.WARN), start=1):
        node._publish_arm(ArmEstimate(level, f'fit at {level.name}', 1))
        assert ros_graph.spin_until(lambda n=count: len(arm_params) == n, 10.0)
    assert [m.status[0].level for m in arm_params] == [b'\x01', b'\x00', b'\x01']
    assert node.arm_updates == 3


def test_a_malformed_joint_state_never_makes_the_node_an_arm(ros_graph):
    # 3 names for 1 position once switched it to an arm for good: every drop test after it
    # was "no ring-down yet".
    node = _identifier(ros_graph)
    malformed = _joint_state(1.0, [0.1])
    malformed.name = ['joint_1', 'joint_2', 'joint_3']
    node._on_joint_state(malformed)
    assert node.joints.current is None and node.bad_joint_states == 1
    node._on_joint_state(_joint_state(1.1, [0.1, 0.2]))  # a well-formed one is taken
    assert node.joints.current is not None and node.bad_joint_states == 1


@pytest.mark.parametrize('kg', [1e6, 1e300])
def test_a_load_the_beam_cannot_carry_is_no_reading(ros_graph, capfd, kg):
    # Read before a release, 1e300 kg once made /beam_params OK with k_tE 8.6e302 (1e6 kg:
    # 8.6e8), which killed an adopting simulator.
    node = _identifier(ros_graph)
    node._on_load(Float64(data=4.5))
    node._on_load(Float64(data=kg))
    assert node.window.snapshot().loads.kg.tolist() == [4.5]
    err = capfd.readouterr().err
    assert f'/tip_load: {kg!r} kg refused: the beam cannot carry it' in err
    assert 'keeping 4.5 kg (1 refused so far)' in err and node.refusals['/tip_load'] == 1
    node._on_load(Float64(data=kg))  # counted, said again only after the warning period
    assert node.refusals['/tip_load'] == 2 and 'refused' not in capfd.readouterr().err
