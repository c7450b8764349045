import math
import subprocess
import sys
import threading
from pathlib import Path

import pytest
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import PoseStamped
from harness import ros_env

from lumpbeam_ros.bagio import BagReader
from lumpbeam_ros.errors import LumpbeamError
from lumpbeam_ros.model.chain import LumpedChain
from lumpbeam_ros.model.modes import chain_modes
from lumpbeam_ros.model.parameters import BeamParameters, DropTestConfig
from lumpbeam_ros.nodes.identifier_node import STATUS_NAME, IdentifierNode
from lumpbeam_ros.nodes.player import Player
from lumpbeam_ros.resources import config_path
from lumpbeam_ros.synthetic.drop_test import SynthOptions, write_drop_test_bag

ROOT = Path(__file__).resolve().parents[2]


def _statuses(messages):
    out = []
    for msg in messages:
        assert len(msg.status) == 1
        status = msg.status[0]
        assert status.name == STATUS_NAME and status.hardware_id == 'beam'
        out.append((status.level[0], status.message, {kv.key: kv.value for kv in status.values}))
    return out


def test_replayed_drop_test_gives_ok_estimates(ros_graph, tmp_path):
    bag = tmp_path / 'drop'
    write_drop_test_bag(bag, BeamParameters(), DropTestConfig(), SynthOptions(duration_s=11.5))
    truth = chain_modes(LumpedChain.from_beam(BeamParameters(), 0.0)).natural_frequency_hz[0]
    node = IdentifierNode(
        context=ros_graph.context,
        parameter_overrides={'use_sim_time': True, 'publish_rate_hz': 4.0},
    )
    ros_graph.add_node(node)
    params = ros_graph.collect('/beam_params', DiagnosticArray, 100)
    player = Player(
        BagReader(bag), ['/tip_pose', '/tip_load'], rate=4.0, context=ros_graph.context
    )
    ros_graph.spin_for(0.5)  # discovery
    thread = threading.Thread(target=player.play)
    thread.start()
    ros_graph.spin_until(lambda: not thread.is_alive(), 15.0)
    thread.join()
    ros_graph.spin_for(0.3)
    statuses = _statuses(params)
    assert len(statuses) >= 20  # 4 Hz on the bag's clock for 11.5 s
    ok = [values for level, _, values in statuses if level == 0]
    assert ok, [message for _, message, _ in statuses][-3:]
    last = ok[-1]
    assert abs(float(last['natural_frequency_hz']) / truth - 1.0) < 5e-3
    assert float(last['release_time_s']) == pytest.approx(2.0, abs=0.02)
    assert last['release_source'] == 'tip_load'
    # SPEC section 3: every float is a repr, every key has its std.
    for key in ('natural_frequency_hz', 'damping_ratio', 'stiffness_total_nm_per_rad'):
        assert repr(float(last[key])) == last[key] and float(last[f'{key}_std']) > 0
    for key in ('window_start_s', 'window_end_s', 'cycles', 'method'):
        assert key in last
    assert float(last['window_end_s']) <= 11.5 and last['samples_wrong_frame'] == '0'


def _pose(stamp, z, frame='beam_base', pitch_w=1.0):
    msg = PoseStamped()
    msg.header.frame_id = frame
    msg.header.stamp.sec, nanosec = divmod(int(round(stamp * 1e9)), 1_000_000_000)
    msg.header.stamp.nanosec = nanosec
    msg.pose.position.x, msg.pose.position.z = 2.3, z
    msg.pose.orientation.w = pitch_w
    return msg


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


def test_parameters_are_validated():
    import rclpy
    from rclpy.context import Context

    context = Context()
    rclpy.init(context=context, domain_id=0)
    try:
        for overrides, problem in [
            ({'window.length_s': -1.0}, 'window.length_s: must be positive'),
            ({'fit.max_modes': 3}, 'fit.max_modes'),
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


def test_main_takes_the_params_file_and_rejects_a_bad_one(ros_graph, tmp_path):
    env = ros_env(ros_graph.domain_id)
    env['PYTHONPATH'] = str(ROOT)
    command = [sys.executable, '-m', 'lumpbeam_ros.nodes.identifier_node', '--ros-args']
    params = ros_graph.collect('/beam_params', DiagnosticArray, 10)
    good = [*command, '--params-file', str(config_path('identifier.yaml'))]
    process = subprocess.Popen([*good, '-p', 'publish_rate_hz:=10.0'], env=env)
    try:
        assert ros_graph.spin_until(lambda: len(params) >= 2, 15.0)
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
