"""ROS 2 YAML launch files read without ROS's launch: the shipped ones, and what is refused."""

from pathlib import Path

import pytest

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import NODE_NAMES
from lumpbeam_ros.base.resources import share_dir
from lumpbeam_ros.nodes.launch_file import (
    NodeLaunch,
    parse_assignments,
    read_launch_file,
    substitute,
)

LAUNCH = Path(__file__).resolve().parents[2] / 'launch'
SHIPPED = sorted(LAUNCH.glob('*.launch.yaml'))


def test_the_three_graphs_are_shipped():
    assert {p.name for p in SHIPPED} == {
        'drop_test.launch.yaml',
        'arm_loop.launch.yaml',
        'camera.launch.yaml',
    }


@pytest.mark.parametrize('path', SHIPPED, ids=lambda p: p.name)
def test_each_shipped_file_starts_package_nodes_with_files_that_exist(path):
    plan = read_launch_file(path)
    assert plan.nodes and all(node.executable in NODE_NAMES for node in plan.nodes)
    for node in plan.nodes:
        argv = node.argv()
        files = [argv[i + 1] for i, arg in enumerate(argv) if arg == '--params-file']
        assert all(Path(f).is_file() for f in files), files


def test_arguments_are_substituted_and_set_from_the_command_line(tmp_path):
    plan = read_launch_file(
        LAUNCH / 'arm_loop.launch.yaml', {'arm_config': 'my_arm.yaml', 'use_sim_time': 'true'}
    )
    simulator = plan.nodes[0].argv()
    assert 'arm_config:=my_arm.yaml' in simulator and 'use_sim_time:=true' in simulator
    shaper = plan.nodes[2].argv()
    assert 'unshaped_until_estimate:=true' in shaper  # a YAML boolean, as ROS writes it
    default = read_launch_file(LAUNCH / 'arm_loop.launch.yaml')
    assert default.arguments['arm_config'] == str(share_dir() / 'config' / 'arm_rotary.yaml')


def test_a_node_is_renamed_and_namespaced_as_ros2_launch_does():
    node = NodeLaunch('camera_node', 'cam_b', '/beam_b', ('x',), ('-r', 'a:=b'))
    assert node.argv() == [
        'x',
        '--ros-args',
        '-r',
        '__node:=cam_b',
        '-r',
        '__ns:=/beam_b',
        '-r',
        'a:=b',
    ]
    assert NodeLaunch('camera_node').argv() == [] and NodeLaunch('camera_node').label == (
        'camera_node'
    )


def test_substitutions(monkeypatch):
    monkeypatch.setenv('LUMPBEAM_TEST_VALUE', 'seven')
    assert substitute('$(var a)/$(env LUMPBEAM_TEST_VALUE)', {'a': 'x'}, 'here') == 'x/seven'
    assert substitute('$(env LUMPBEAM_NO_SUCH_VALUE fallback)', {}, 'here') == 'fallback'
    assert substitute('$(find-pkg-share lumpbeam_ros)', {}, 'here') == str(share_dir())


def _file(tmp_path, text):
    path = tmp_path / 'x.launch.yaml'
    path.write_text(text)
    return path


NODE = '- node:\n    pkg: lumpbeam_ros\n    exec: shaper_node\n'


@pytest.mark.parametrize(
    ('text', 'given', 'problem'),
    [
        ('nodes: []', {}, 'no top-level launch: list'),
        ('launch:\n- include:\n    file: a.yaml\n', {}, "tag 'include' is not read"),
        (
            'launch:\n- node:\n    pkg: demo_nodes_cpp\n    exec: talker\n',
            {},
            "pkg 'demo_nodes_cpp'",
        ),
        ('launch:\n- node:\n    pkg: lumpbeam_ros\n    exec: talker\n', {}, "exec 'talker'"),
        (f'launch:\n{NODE}    respawn: true\n', {}, "attribute 'respawn'"),
        (f'launch:\n{NODE}    output: $(var o)\n', {}, '$(var o): no such launch argument'),
        (f'launch:\n{NODE}    output: $(command ls)\n', {}, '$(command ls) is not read'),
        ('launch:\n- arg:\n    name: a\n' + NODE, {}, "'a' has no default"),
        ('launch:\n' + NODE, {'b': '1'}, "no launch argument 'b'"),
        ('launch:\n- arg:\n    name: a\n    default: x\n', {}, 'starts no node'),
        (f'launch:\n{NODE}    param:\n    - name: x\n', {}, 'expected name: and value:'),
        (f'launch:\n{NODE}    remap:\n    - from: a\n', {}, 'needs from: and to:'),
        (f'launch:\n{NODE}    output: printer\n', {}, "output 'printer'"),
    ],
)
def test_what_lumpbeam_launch_cannot_run_is_one_clear_error(tmp_path, text, given, problem):
    with pytest.raises(LumpbeamError, match='x.launch.yaml') as caught:
        read_launch_file(_file(tmp_path, text), given)
    assert problem in str(caught.value) and '\n' not in str(caught.value)


def test_assignments():
    assert parse_assignments(['a:=1', 'b:=x:=y']) == {'a': '1', 'b': 'x:=y'}
    with pytest.raises(LumpbeamError, match='expected NAME:=VALUE'):
        parse_assignments(['a=1'])
