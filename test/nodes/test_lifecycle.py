"""run_node: a node process's start, stop, error line and counts."""

from __future__ import annotations

import pytest
from rclpy.node import Node

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
