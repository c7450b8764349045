"""run_node: a node process's start, stop, error line and counts."""

from __future__ import annotations

import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import rclpy
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import PoseStamped
from harness import ros_env, start_process, stop_with
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.node import Node
from std_msgs.msg import Float64

from lumpbeam_ros.base import interrupts
from lumpbeam_ros.base.errors import ConfigError, LumpbeamError
from lumpbeam_ros.base.interface import (
    BEAM_PARAMS,
    DIAGNOSTICS,
    MODEL_DISCREPANCY,
    TIP_POSE,
    TIP_POSE_PREDICTED,
)
from lumpbeam_ros.core.model.parameters import load_beam_config
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, write_drop_test_bag
from lumpbeam_ros.core.synthetic.images import ImageOptions
from lumpbeam_ros.nodes.counts import COUNTS_DIR_ENV, read_counts
from lumpbeam_ros.nodes.lifecycle import CONFIG_ERROR, run_node, spin_events

ROOT = Path(__file__).resolve().parents[2]
SIGNALS = [signal.SIGINT, signal.SIGTERM]


@pytest.fixture
def counts_dir(tmp_path, monkeypatch, ros_domain_id):
    monkeypatch.setenv('ROS_DOMAIN_ID', str(ros_domain_id))
    monkeypatch.setenv(COUNTS_DIR_ENV, str(tmp_path / 'counts'))
    return tmp_path / 'counts'


class _Counting(Node):
    def __init__(self) -> None:
        super().__init__('counting_node')
        self.sent = 3


@pytest.mark.parametrize('stop', [KeyboardInterrupt, SystemExit])
def test_a_stopped_node_writes_its_counts(counts_dir, stop):
    def run(node: _Counting) -> None:
        node.sent = 7
        raise stop

    if stop is SystemExit:
        with pytest.raises(SystemExit):
            run_node('counting_node', _Counting, lambda n: {'/x': n.sent}, [], run=run)
    else:
        assert run_node('counting_node', _Counting, lambda n: {'/x': n.sent}, [], run=run) == 0
    # However it stopped, what it published is counted.
    assert read_counts(counts_dir)['counting_node']['published'] == {'/x': 7}


@pytest.mark.parametrize(
    'error',
    [
        ConfigError('node parameters', 'rate_hz', 'must be positive, got -1.0'),
        LumpbeamError('no bag'),
    ],
)
@pytest.mark.parametrize('when', ['build', 'run'])
def test_a_configuration_error_is_one_line_and_exit_2(counts_dir, capsys, error, when):
    def make() -> _Counting:
        if when == 'build':
            raise error
        return _Counting()

    def run(node: _Counting) -> None:
        raise error

    assert run_node('counting_node', make, lambda n: {'/x': n.sent}, [], run=run) == CONFIG_ERROR
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f'counting_node: error: {error}']
    # A node that was never built published nothing and writes no counts.
    assert ('counting_node' in read_counts(counts_dir)) == (when == 'run')


class _Publishing(_Counting):
    def __init__(self) -> None:
        super().__init__()
        self.sent = 0
        self.publisher = self.create_publisher(Float64, 'x', 1)

    def publish(self) -> None:
        self.publisher.publish(Float64(data=1.0))
        self.sent += 1


def test_a_shutdown_that_cuts_into_a_publish_is_a_quiet_stop(counts_dir, capsys):
    def run(node: _Publishing) -> None:
        node.publish()
        # What rclpy's SIGINT/SIGTERM handler does while a timer callback runs.
        rclpy.shutdown()
        node.publish()

    assert run_node('counting_node', _Publishing, lambda n: {'/x': n.sent}, [], run=run) == 0
    assert capsys.readouterr().err == ''
    assert read_counts(counts_dir)['counting_node']['published'] == {'/x': 1}


@pytest.mark.parametrize('signalled', [True, False], ids=['after a signal', 'without one'])
def test_a_runtime_error_is_the_stop_only_after_a_signal(counts_dir, monkeypatch, signalled):
    # What pybind11 makes of an interrupt raised while it converts a call's arguments
    # (seen when SIGTERM reached an identifier taking a message on a loaded machine).
    monkeypatch.setattr(interrupts, '_received', [])
    monkeypatch.setattr(sys, 'unraisablehook', sys.unraisablehook)

    def run(node: _Publishing) -> None:
        if signalled:
            try:
                interrupts.raise_interrupt(signal.SIGTERM, None)
            except interrupts.SignalInterrupt:
                pass
        raise RuntimeError("Unable to convert call argument '0' to Python object")

    def stop() -> int:
        return run_node('counting_node', _Publishing, lambda n: {'/x': n.sent}, [], run=run)

    if signalled:
        assert stop() == 0
    else:
        with pytest.raises(RuntimeError, match='Unable to convert'):
            stop()


def test_a_signal_that_reaches_python_after_the_spin_ended_is_the_stop(counts_dir, monkeypatch):
    # rclpy's handler shuts the context down first, which ends the spin (here: a publish
    # fails); Python's handler, run at its next check, then raised the interrupt inside
    # run_node's except clause (seen in CI: exit 1 with a traceback, a node stopped by SIGINT).
    monkeypatch.setattr(interrupts, '_received', [])
    monkeypatch.setattr(sys, 'unraisablehook', sys.unraisablehook)
    ok = rclpy.ok

    def late_interrupt(**kwargs: object) -> bool:
        interrupts.raise_interrupt(signal.SIGINT, None)
        return ok(**kwargs)

    def run(node: _Publishing) -> None:
        node.publish()
        rclpy.shutdown()
        monkeypatch.setattr(rclpy, 'ok', late_interrupt)
        node.publish()

    assert run_node('counting_node', _Publishing, lambda n: {'/x': n.sent}, [], run=run) == 0
    assert read_counts(counts_dir)['counting_node']['published'] == {'/x': 1}


def test_a_signal_during_the_cleanup_still_writes_the_counts(counts_dir, monkeypatch):
    monkeypatch.setattr(interrupts, '_received', [])
    monkeypatch.setattr(sys, 'unraisablehook', sys.unraisablehook)

    def published(node: _Publishing) -> dict[str, int]:
        signal.raise_signal(signal.SIGTERM)
        return {'/x': node.sent}

    def run(node: _Publishing) -> None:
        node.publish()

    assert run_node('counting_node', _Publishing, published, [], run=run) == 0
    assert read_counts(counts_dir)['counting_node']['published'] == {'/x': 1}
    # The signal was recorded, not lost, and the handlers are back as they were.
    assert interrupts.interrupted()
    assert signal.getsignal(signal.SIGTERM) is not interrupts.record_signal


def test_a_middleware_error_while_running_is_not_hidden(counts_dir):
    def run(node: _Publishing) -> None:
        raise _rclpy.RCLError('failed to take a message')

    with pytest.raises(_rclpy.RCLError, match='failed to take'):
        run_node('counting_node', _Publishing, lambda n: {'/x': n.sent}, [], run=run)
    assert read_counts(counts_dir)['counting_node']['published'] == {'/x': 0}


@pytest.mark.parametrize('error', [interrupts.SignalInterrupt(signal.SIGTERM), ValueError('bad')])
def test_what_an_events_callback_raises_leaves_the_spin_unlogged(ros_graph, capfd, error):
    node = Node('raising_node', context=ros_graph.context)
    calls = []

    def tick() -> None:
        calls.append(1)
        raise error

    node.create_timer(0.01, tick)
    node.create_subscription(Float64, 'x', lambda _msg: calls.append(2), 10)
    try:
        with pytest.raises(type(error)):
            spin_events(node)
    finally:
        node.destroy_node()
    assert calls == [1]
    # The events executor logs what leaves a callback as FATAL, a stop signal included.
    assert capfd.readouterr().err == ''


#: A node whose callback computes without end (a solve that never converges).
BUSY_NODE = """
import sys
from rclpy.node import Node
from lumpbeam_ros.nodes.lifecycle import run_node

def run(node):
    print('busy', flush=True)
    while True:
        pass

sys.exit(run_node('busy_node', lambda: Node('busy_node'), lambda n: {}, [], run=run))
"""


@pytest.mark.parametrize('ignored', [False, True], ids=['', 'SIGINT ignored at start'])
@pytest.mark.parametrize('sig', SIGNALS, ids=lambda s: s.name)
def test_a_signal_interrupts_a_callback_that_computes(ros_domain_id, tmp_path, sig, ignored):
    """SIGTERM, and SIGINT in a background job (started with SIGINT ignored), too."""
    env = ros_env(ros_domain_id, tmp_path)
    env['PYTHONPATH'] = str(ROOT)
    handler = signal.SIG_IGN if ignored else signal.SIG_DFL
    process = subprocess.Popen(
        [sys.executable, '-c', BUSY_NODE],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=lambda: signal.signal(signal.SIGINT, handler),
    )
    assert process.stdout is not None
    assert process.stdout.readline() == 'busy\n'
    code, _, stderr = stop_with(process, sig)
    assert code == 0 and stderr == ''


@pytest.fixture(scope='module')
def filmed_bag(tmp_path_factory):
    """An 8 s drop test filmed at 320 x 240: 1441 frames for the camera node to track.

    The node tracks a bag as fast as it can (about 400 frames/s on an idle machine) and then
    exits: the bag must last longer than the test's subscription takes to match the node's
    publisher, or the signal finds it done rather than working.
    """
    path = tmp_path_factory.mktemp('filmed') / 'bag'
    beam, drop = load_beam_config()
    write_drop_test_bag(
        path, beam, drop, SynthOptions(duration_s=8.0), images=ImageOptions(320, 240)
    )
    return path


#: Each node, what it is given to work on, what it publishes while it works and whether it
#: needs /tip_pose for that. A live camera node (no bag) spins on the events executor
#: (lifecycle.spin_events) and shows it spins by its diagnostics.
NODES = {
    'camera': (['-p', 'bag_path:={bag}'], TIP_POSE, PoseStamped, False),
    'camera live': (['-p', 'diagnostics_period_s:=0.1'], DIAGNOSTICS, DiagnosticArray, False),
    'identifier': (['-p', 'publish_rate_hz:=20.0'], BEAM_PARAMS, DiagnosticArray, True),
    'simulator': ([], TIP_POSE_PREDICTED, PoseStamped, False),
    'diagnosis': (['-p', 'status_period_s:=0.2'], MODEL_DISCREPANCY, DiagnosticArray, True),
}


@pytest.mark.parametrize('sig', SIGNALS, ids=lambda s: s.name)
@pytest.mark.parametrize('node', list(NODES))
def test_a_node_stops_within_the_bound_while_it_works(ros_graph, filmed_bag, node, sig):
    extra, topic, msgtype, fed = NODES[node]
    got = ros_graph.collect(topic, msgtype, 100)
    pose = PoseStamped()
    pose.header.frame_id = 'beam_base'
    pose.pose.orientation.w = 1.0

    def working() -> bool:
        if fed:
            pose.header.stamp.nanosec = (pose.header.stamp.nanosec + 5_000_000) % 10**9
            pose.header.stamp.sec += pose.header.stamp.nanosec == 0
            ros_graph.publish(TIP_POSE, pose, 100)
        return len(got) >= 3

    env = ros_env(ros_graph.domain_id)
    env['PYTHONPATH'] = str(ROOT)
    argv = [a.format(bag=filmed_bag) for a in extra]
    module = f'lumpbeam_ros.nodes.{node.split()[0]}_node'
    process = start_process(env, module, '--ros-args', *argv)
    try:
        worked = ros_graph.spin_until(working, 60.0)
    finally:
        code, _, stderr = stop_with(process, sig)
    assert worked, stderr
    assert code == 0, stderr
    assert 'Traceback' not in stderr


NODE_NAMES = ['camera_node', 'identifier_node', 'simulator_node', 'diagnosis_node', 'shaper_node']


@pytest.mark.parametrize('node', NODE_NAMES)
def test_help_lists_the_parameters_and_starts_nothing(node, capsys):
    from lumpbeam_ros.nodes.params.reference import SCHEMAS

    schema = next(s for s in SCHEMAS if s.node == node)
    module = __import__(f'lumpbeam_ros.nodes.{node}', fromlist=['main'])
    assert module.main([node, '--help']) == 0
    out = capsys.readouterr().out
    assert out.startswith(f'usage: {node} ')
    for spec in schema:
        assert f'  {spec.name} ({spec.kind}, default ' in out


@pytest.mark.parametrize(
    ('text', 'problem'),
    [
        (None, 'no such file'),
        ('x: [', 'not valid YAML at line'),
        ('just text', 'expected a mapping of node names'),
    ],
)
def test_a_bad_params_file_names_the_file_and_exits_2(tmp_path, capsys, text, problem):
    path = tmp_path / 'params.yaml'
    if text is not None:
        path.write_text(text)
    module = __import__('lumpbeam_ros.nodes.shaper_node', fromlist=['main'])
    code = module.main(['shaper_node', '--ros-args', '--params-file', str(path)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == CONFIG_ERROR
    assert len(err) == 1 and err[0].startswith(f'shaper_node: error: {path}') and problem in err[0]


def test_an_unknown_parameter_is_warned_about_and_the_node_says_it_is_ready(ros_domain_id):
    env = ros_env(ros_domain_id)
    env['PYTHONPATH'] = str(ROOT)
    process = start_process(
        env, 'lumpbeam_ros.nodes.shaper_node', '--ros-args', '-p', 'no_such_param:=1'
    )
    lines = []
    try:
        for line in process.stderr:
            lines.append(line)
            if line.rstrip().endswith('ready'):
                break
    finally:
        code, _, stderr = stop_with(process, signal.SIGINT)
    text = ''.join(lines) + stderr
    assert "unknown parameter 'no_such_param': not a parameter of shaper_node" in text
    assert any(line.rstrip().endswith('ready') for line in lines), text
    assert code == 0


def _children(pid: int) -> set[int]:
    """Every descendant of a process (Linux's /proc children lists)."""
    found: set[int] = set()
    todo = [pid]
    while todo:
        parent = todo.pop()
        for task in Path(f'/proc/{parent}/task').glob('*'):
            try:
                kids = {int(k) for k in (task / 'children').read_text().split()}
            except OSError:
                continue
            todo += sorted(kids - found)
            found |= kids
    return found


def _alive(pid: int) -> bool:
    try:
        state = Path(f'/proc/{pid}/stat').read_text().split(') ', 1)[1][0]
    except (OSError, IndexError):
        return False
    return state != 'Z'


#: A hang, not a slow stop, is what this catches (the stop takes 0.2 to 2 s here).
STOP_BOUND_S = 10.0


@pytest.mark.parametrize('sig', SIGNALS, ids=lambda s: s.name)
@pytest.mark.parametrize('node', NODE_NAMES)
def test_a_signal_to_the_process_group_stops_the_node_and_its_children(ros_domain_id, node, sig):
    import os
    import threading

    env = ros_env(ros_domain_id)
    env['PYTHONPATH'] = str(ROOT)
    process = subprocess.Popen(
        [sys.executable, '-m', f'lumpbeam_ros.nodes.{node}'],
        env=env,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    lines: list[str] = []
    for line in process.stderr:
        lines.append(line)
        if line.rstrip().endswith('ready'):
            break
    threading.Thread(target=lambda: lines.extend(process.stderr), daemon=True).start()
    time.sleep(1.0)  # the diagnosis node's worker starts after the node is ready
    family = _children(process.pid)
    started = time.monotonic()
    os.killpg(process.pid, sig)
    while time.monotonic() - started < STOP_BOUND_S and (
        process.poll() is None or any(_alive(pid) for pid in family)
    ):
        time.sleep(0.05)
    left = [pid for pid in family if _alive(pid)]
    if process.poll() is None or left:
        os.killpg(process.pid, signal.SIGKILL)
        for pid in left:
            os.kill(pid, signal.SIGKILL)
    assert process.wait(5) == 0 and not left, ''.join(lines)[-2000:]
