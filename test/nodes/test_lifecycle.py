"""run_node: a node process's start, stop, error line and counts."""

from __future__ import annotations

import pytest
import rclpy
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.node import Node
from std_msgs.msg import Float64

from lumpbeam_ros.errors import ConfigError, LumpbeamError
from lumpbeam_ros.nodes.counts import COUNTS_DIR_ENV, read_counts
from lumpbeam_ros.nodes.lifecycle import CONFIG_ERROR, run_node


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


def test_a_middleware_error_while_running_is_not_hidden(counts_dir):
    def run(node: _Publishing) -> None:
        raise _rclpy.RCLError('failed to take a message')

    with pytest.raises(_rclpy.RCLError, match='failed to take'):
        run_node('counting_node', _Publishing, lambda n: {'/x': n.sent}, [], run=run)
    assert read_counts(counts_dir)['counting_node']['published'] == {'/x': 0}
