import os
import sys
import time

import pytest

from lumpbeam_ros.apps.demo import graph as graph_module
from lumpbeam_ros.apps.demo.graph import (
    DOMAIN_IDS,
    ProcessGraph,
    node_command,
    python_command,
    wait_for_graph,
    wait_for_quiet,
)
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.nodes.ros_domain import claim_domain_id


def _python(code):
    return [sys.executable, '-c', code]


def _alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    # A zombie (exited, not yet reaped by its parent) counts as gone.
    with open(f'/proc/{pid}/stat') as stat:
        return stat.read().split(')')[-1].split()[0] != 'Z'


def _wait_for_line(path, timeout=10.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        text = path.read_text() if path.exists() else ''
        if text.strip():
            return text.strip().splitlines()[0]
        time.sleep(0.02)
    raise AssertionError(f'{path} stayed empty')


def test_an_error_in_the_block_stops_children_and_grandchildren(tmp_path):
    spawner = (
        'import subprocess, sys, time\n'
        "p = subprocess.Popen([sys.executable, '-c', 'import time; time.sleep(60)'])\n"
        'print(p.pid, flush=True)\n'
        'time.sleep(60)\n'
    )
    with pytest.raises(RuntimeError, match='boom'):
        with ProcessGraph(tmp_path, domain_id=7) as graph:
            child = graph.start('spawner', _python(spawner))
            grandchild = int(_wait_for_line(child.log_path))
            raise RuntimeError('boom')
    assert child.process.returncode is not None
    deadline = time.monotonic() + 5.0
    while _alive(grandchild) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not _alive(grandchild)


def test_children_get_the_private_domain_and_local_discovery(tmp_path):
    code = (
        'import os; env = os.environ; '
        "print(env['ROS_DOMAIN_ID'], env['ROS_AUTOMATIC_DISCOVERY_RANGE'])"
    )
    with ProcessGraph(tmp_path, domain_id=42) as graph:
        graph.start('env', _python(code))
        assert graph.wait('env', 10.0) == 0
    assert (tmp_path / 'env.log').read_text().split() == ['42', 'LOCALHOST']


def test_interrupt_stops_with_sigint_and_kills_what_ignores_it(tmp_path, monkeypatch):
    stubborn = (
        'import signal, time\n'
        'signal.signal(signal.SIGINT, signal.SIG_IGN)\n'
        "print('ready', flush=True)\n"
        'time.sleep(60)\n'
    )
    # The polite child installs its handler as rclpy.init does for every node, so the test
    # holds when pytest itself was started with SIGINT ignored (a background job of a
    # non-interactive shell), which a plain Python child would inherit.
    polite = (
        'import signal, time\n'
        'signal.signal(signal.SIGINT, signal.default_int_handler)\n'
        "print('ready', flush=True)\n"
        'try:\n'
        '    time.sleep(60)\n'
        'except KeyboardInterrupt:\n'
        '    pass\n'
    )
    with ProcessGraph(tmp_path) as graph:
        good = graph.start('polite', _python(polite))
        bad = graph.start('stubborn', _python(stubborn))
        _wait_for_line(good.log_path)
        _wait_for_line(bad.log_path)
        assert graph.interrupt('polite') == 0
        with pytest.raises(LumpbeamError, match='stubborn did not stop within 0.5 s'):
            graph.interrupt('stubborn', grace_s=0.5)
        assert not bad.running()


def test_failures_are_one_line_errors_with_the_log_tail(tmp_path):
    with ProcessGraph(tmp_path) as graph:
        graph.start('fails', _python("print('bad bag'); raise SystemExit(3)"))
        with pytest.raises(LumpbeamError, match=r'fails failed with code 3: bad bag'):
            graph.wait('fails', 10.0)
        graph.start('sleeps', _python('import time; time.sleep(30)'))
        with pytest.raises(LumpbeamError, match='sleeps did not finish within 0.2 s'):
            graph.wait('sleeps', 0.2)
        graph.start('quits', _python('pass'))
        time.sleep(0.5)
        with pytest.raises(LumpbeamError, match='quits exited early with code 0'):
            graph.wait('sleeps', 5.0, watch=['quits'])
        with pytest.raises(LumpbeamError, match='already running'):
            graph.start('sleeps', _python('pass'))
        with pytest.raises(LumpbeamError, match='cannot start nothing'):
            graph.start('nothing', ['/no/such/program'])


def test_wait_for_graph_names_what_is_missing(tmp_path):
    with ProcessGraph(tmp_path) as graph:
        with pytest.raises(LumpbeamError, match='missing node ghost, 1 subscriber.s. of /x'):
            wait_for_graph(graph, ['ghost'], {'/x': 1}, timeout_s=0.5)


def test_wait_for_graph_sees_a_node_child(tmp_path):
    with ProcessGraph(tmp_path) as graph:
        graph.start(
            'simulator', node_command('lumpbeam_ros.nodes.simulator_node', '-p', 'rate_hz:=50.0')
        )
        wait_for_graph(
            graph,
            ['simulator_node'],
            {'/tip_load': 2},
            30.0,
            announce={'/tip_load': 'std_msgs/msg/Float64'},
        )
        # The node is in the graph before its constructor has finished: a SIGINT now would
        # stop it before it says it is ready.
        log = tmp_path / 'simulator.log'
        deadline = time.monotonic() + 30.0
        while 'simulation started' not in log.read_text() and time.monotonic() < deadline:
            time.sleep(0.1)
        # It keeps publishing on wall time from then on: never quiet, the wait ends at its
        # timeout.
        heard = wait_for_quiet(
            graph, {'/tip_pose_predicted': 'geometry_msgs/msg/PoseStamped'}, 0.5, 5.0
        )
        assert heard['/tip_pose_predicted'] > 0
        assert graph.interrupt('simulator') == 0
    assert '[simulator_node]: ready' in log.read_text()


def test_wait_for_quiet_returns_on_a_topic_without_publisher(tmp_path, monkeypatch):
    monkeypatch.setattr(graph_module, 'DISCOVERY_ALLOWANCE_S', 0.2)
    with ProcessGraph(tmp_path) as graph:
        heard = wait_for_quiet(graph, {'/nobody': 'std_msgs/msg/Float64'}, 0.2, 60.0)
    assert heard == {'/nobody': 0}


def test_commands_and_domain_ids():
    assert python_command('a.b', 'x') == [sys.executable, '-m', 'a.b', 'x']
    command = node_command('lumpbeam_ros.nodes.camera_node', '-p', 'x:=1')
    assert command[:2] == [sys.executable, '-c']
    assert 'from lumpbeam_ros.nodes.scripts import camera_node' in command[2]
    assert command[3:] == ['--ros-args', '-p', 'x:=1']
    assert 0 not in DOMAIN_IDS and graph_module.STOP_GRACE_S > 0


def test_graphs_open_together_hold_different_domains_until_closed(tmp_path):
    with ProcessGraph(tmp_path / 'a') as first, ProcessGraph(tmp_path / 'b') as second:
        assert first.domain_id != second.domain_id
        assert {first.domain_id, second.domain_id} <= set(DOMAIN_IDS)
        held = first.domain_id
    with claim_domain_id([held]) as claim:  # closing the graph freed its domain
        assert claim.domain_id == held
    with ProcessGraph(tmp_path / 'c', domain_id=held) as given:
        assert given.domain_id == held
