"""The design counts stay where the refactoring left them (tools/design_counts.py)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _tool():
    spec = importlib.util.spec_from_file_location(
        'design_counts', ROOT / 'tools' / 'design_counts.py'
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_interface_names_are_written_once():
    tool = _tool()
    assert '/tip_pose' in tool.interface_names(ROOT) and 'beam_base' in tool.interface_names(ROOT)
    assert tool.literal_uses(ROOT) == []


def test_a_literal_outside_the_interface_is_found(tmp_path):
    tool = _tool()
    package = tmp_path / 'lumpbeam_ros'
    package.mkdir()
    (package / 'interface.py').write_text((ROOT / 'lumpbeam_ros' / 'interface.py').read_text())
    (package / 'node.py').write_text(
        '"""Uses \'/tip_pose\' in a docstring only."""\nX = \'/tip_pose\'\n'
    )
    assert tool.literal_uses(tmp_path) == ["lumpbeam_ros/node.py:2: '/tip_pose'"]


def test_parameters_are_declared_only_from_the_schemas():
    assert (
        _tool()._grep(ROOT, r'\.declare_parameters?\(', ('lumpbeam_ros/nodes/ros_parameters.py',))
        == []
    )


def test_the_product_imports_nothing_of_the_lab():
    assert _tool().lab_imports(ROOT) == []


def test_a_lab_import_by_the_product_is_found_and_the_cli_may_run_the_lab(tmp_path):
    tool = _tool()
    for folder in ('vision', 'nodes', 'cli'):
        (tmp_path / 'lumpbeam_ros' / folder).mkdir(parents=True)
    (tmp_path / 'lumpbeam_ros' / 'vision' / 'scores.py').write_text(
        'from lumpbeam_lab.camera.accuracy import score\n'
    )
    (tmp_path / 'lumpbeam_ros' / 'nodes' / 'node.py').write_text(
        'def f():\n    import lumpbeam_lab.doctor\n'
    )
    (tmp_path / 'lumpbeam_ros' / 'cli' / 'bench.py').write_text(
        'from lumpbeam_lab.bench.runner import run_suites\n'
    )
    assert tool.lab_imports(tmp_path) == [
        'lumpbeam_ros/nodes/node.py:2: lumpbeam_lab.doctor',
        'lumpbeam_ros/vision/scores.py:1: lumpbeam_lab.camera.accuracy',
    ]
