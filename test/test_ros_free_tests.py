"""The tests of the ROS-free floors import no ROS, so they run in a plain Python.

``test/conftest.py`` imports ROS only inside the ROS fixtures; a test module of the ground
floor, the core, the nodes' schemas or the ROS-free applications that imported rclpy (or the
launch-free harness, which does) would make its whole package need ROS again.
"""

from __future__ import annotations

import ast
import re
import subprocess
import sys
from pathlib import Path

import pytest

TEST = Path(__file__).resolve().parent

#: The test folders of the ROS-free floors (they mirror ``tools/test_modules.py``'s parts).
ROS_FREE = ('base', 'core', 'nodes/params', 'apps/campaign', 'apps/plots', 'apps/report')

_ROS = re.compile(r'^(rclpy|rcl_.*|rmw.*|rosidl.*|.*_msgs|harness)$')


def _imports(path: Path) -> set[str]:
    names = set()
    for node in ast.walk(ast.parse(path.read_text(encoding='utf-8'))):
        if isinstance(node, ast.Import):
            names.update(alias.name.partition('.')[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module.partition('.')[0])
    return names


def _modules() -> list[Path]:
    return sorted(p for folder in ROS_FREE for p in (TEST / folder).rglob('*.py'))


@pytest.mark.parametrize('path', _modules(), ids=lambda p: p.relative_to(TEST).as_posix())
def test_a_ros_free_test_module_imports_no_ros(path):
    ros = sorted(name for name in _imports(path) if _ROS.match(name))
    assert not ros, f'{path.relative_to(TEST)} imports {ros}'


def test_the_shared_fixtures_import_no_ros():
    code = (
        'import sys; sys.path.insert(0, sys.argv[1]); import conftest; '
        "print(sorted(m for m in sys.modules if m.partition('.')[0] == 'rclpy'))"
    )
    done = subprocess.run(
        [sys.executable, '-c', code, str(TEST)], capture_output=True, text=True, check=True
    )
    assert done.stdout.strip() == '[]'


def test_the_check_sees_an_import_of_ros(tmp_path):
    module = tmp_path / 'test_x.py'
    module.write_text('import numpy\nfrom rclpy.node import Node\nfrom harness import ros_env\n')
    assert {name for name in _imports(module) if _ROS.match(name)} == {'rclpy', 'harness'}
