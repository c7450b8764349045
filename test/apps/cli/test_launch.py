"""``lumpbeam launch``: the shipped launch files start their graphs, and stop together."""

import signal
import time
from pathlib import Path

import pytest
from harness import ros_env, start_process, stop_with

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.nodes.launch_file import read_launch_file

LAUNCH = Path(__file__).resolve().parents[3] / 'launch'


@pytest.mark.parametrize('name', ['camera', 'drop_test', 'arm_loop'])
def test_a_shipped_file_starts_its_nodes_on_the_graph(ros_graph, name):
    path = LAUNCH / f'{name}.launch.yaml'
    wanted = {node.label for node in read_launch_file(path).nodes}
    process = start_process(
        ros_env(ros_graph.domain_id), 'lumpbeam_ros.apps.cli.main', 'launch', str(path)
    )
    seen: set[str] = set()
    try:

        def all_up() -> bool:
            seen.update(ros_graph.node.get_node_names())
            return wanted <= seen

        up = ros_graph.spin_until(all_up, 60.0)
    finally:
        started = time.monotonic()
        code, stdout, stderr = stop_with(process, signal.SIGINT)
        stopped_in = time.monotonic() - started
    assert up, f'saw {sorted(seen)}; {stderr[-2000:]}'
    assert code == 0, stderr[-2000:]
    assert f'lumpbeam launch: stopped {len(wanted)} nodes' in stdout
    assert stopped_in < 10.0 and 'Traceback' not in stderr


def test_a_node_that_fails_stops_the_others_and_is_one_line(
    ros_domain_id, tmp_path, capsys, monkeypatch
):
    for key, value in ros_env(ros_domain_id).items():
        monkeypatch.setenv(key, value)
    path = tmp_path / 'bad.launch.yaml'
    path.write_text(
        'launch:\n'
        '- node:\n    pkg: lumpbeam_ros\n    exec: shaper_node\n'
        '- node:\n    pkg: lumpbeam_ros\n    exec: identifier_node\n'
        '    param:\n    - name: window.length_s\n      value: -1.0\n'
    )
    assert main(['launch', str(path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err[-1] == (
        'lumpbeam launch: error: identifier_node exited with code 2; the other nodes stopped'
    )


def test_a_file_it_cannot_run_is_one_line_and_exit_2(tmp_path, capsys):
    path = tmp_path / 'x.launch.yaml'
    path.write_text('launch:\n- include:\n    file: other.launch.yaml\n')
    assert main(['launch', str(path), 'a:=1']) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "tag 'include' is not read" in err[0]
