"""The design counts stay where the refactoring left them (tools/design_counts.py)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

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
    (package / 'base').mkdir()
    interface = ROOT / 'lumpbeam_ros' / 'base' / 'interface.py'
    (package / 'base' / 'interface.py').write_text(interface.read_text())
    (package / 'node.py').write_text(
        '"""Uses \'/tip_pose\' in a docstring only."""\nX = \'/tip_pose\'\n'
    )
    assert tool.literal_uses(tmp_path) == ["lumpbeam_ros/node.py:2: '/tip_pose'"]


def test_parameters_are_declared_only_from_the_schemas():
    assert (
        _tool()._grep(ROOT, r'\.declare_parameters?\(', ('lumpbeam_ros/nodes/ros_parameters.py',))
        == []
    )


@pytest.fixture(scope='module')
def tool():
    return _tool()


def test_node_parameter_defaults_and_bounds_are_written_once(tool):
    assert tool.repeated_parameter_literals(ROOT) == []


def test_every_declared_parameter_is_read(tool):
    assert tool.unread_parameters(ROOT) == []


def test_an_effect_is_one_record_plus_its_physics(tool):
    assert tool.effect_places(ROOT) == []


def test_the_core_imports_no_lab_module(tool):
    assert tool.lab_imports(ROOT) == []


def _package(tmp_path, files):
    package = tmp_path / 'lumpbeam_ros'
    for name, text in files.items():
        path = package / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    (tmp_path / 'doc').mkdir()
    (tmp_path / 'doc' / 'interfaces.md').write_text((ROOT / 'doc' / 'interfaces.md').read_text())
    return tmp_path


def test_the_counts_find_what_they_count(tool, tmp_path, monkeypatch):
    repo = _package(
        tmp_path,
        {
            'core/vision/config.py': (
                "F = get_float(p, 'camera.focal_length_px', source, 2400.0)\n"
            ),
            'core/vision/other.py': 'class C:\n    focal_length_px: float = 2400.0\n',
            'core/model/table.py': "OFF = {'sensor_scale': 1.0}\n",
            'core/viz/markers.py': 'from lumpbeam_lab.camera import accuracy\n',
            'core/synthetic/cases.py': "CASES = ({'added_mass': 0.3},)\n",  # example cases
        },
    )
    schemas = tool._schemas(ROOT)
    monkeypatch.setattr(tool, '_schemas', lambda repo: schemas)
    assert tool.repeated_parameter_literals(repo) == [
        'camera_node camera.focal_length_px: '
        'lumpbeam_ros/core/vision/config.py:1, lumpbeam_ros/core/vision/other.py:2'
    ]
    assert tool.effect_places(repo) == ['lumpbeam_ros/core/model/table.py:1: a table naming 1']
    assert tool.lab_imports(repo) == ['lumpbeam_ros/core/viz/markers.py:1: lumpbeam_lab.camera']


def test_a_lab_import_anywhere_in_the_product_is_found(tmp_path):
    tool = _tool()
    for folder in ('core/vision', 'nodes', 'apps/cli'):
        (tmp_path / 'lumpbeam_ros' / folder).mkdir(parents=True)
    (tmp_path / 'lumpbeam_ros' / 'core' / 'vision' / 'scores.py').write_text(
        'from lumpbeam_lab.camera.accuracy import score\n'
    )
    (tmp_path / 'lumpbeam_ros' / 'nodes' / 'node.py').write_text(
        'def f():\n    import lumpbeam_lab.mujoco_arm\n'
    )
    (tmp_path / 'lumpbeam_ros' / 'apps' / 'cli' / 'bench.py').write_text(
        'from lumpbeam_lab.bench.runner import run_suites\n'
    )
    assert tool.lab_imports(tmp_path) == [
        'lumpbeam_ros/apps/cli/bench.py:1: lumpbeam_lab.bench.runner',
        'lumpbeam_ros/core/vision/scores.py:1: lumpbeam_lab.camera.accuracy',
        'lumpbeam_ros/nodes/node.py:2: lumpbeam_lab.mujoco_arm',
    ]


def test_bags_are_read_by_the_one_reader_alone(tool):
    assert tool.bag_readers(ROOT) == []


def test_a_reader_of_its_own_is_found(tool, tmp_path):
    repo = _package(
        tmp_path,
        {
            'core/vision/offline.py': 'from mcap.reader import SeekingReader\n',
            'core/bagio/reader.py': (
                'from mcap.stream_reader import StreamReader\n'
                "(length,) = struct.unpack_from('<Q', data, 1)\n"
            ),
            'core/bagio/fastscan.py': "(n,) = struct.unpack_from('<I', first, 12)\n",
        },
    )
    assert tool.bag_readers(repo) == [
        "lumpbeam_ros/core/bagio/fastscan.py:1: (n,) = struct.unpack_from('<I', first, 12)",
        "lumpbeam_ros/core/bagio/reader.py:2: (length,) = struct.unpack_from('<Q', data, 1)",
        'lumpbeam_ros/core/vision/offline.py:1: import mcap.reader',
    ]
    # The fast path with its agreement test is the one kept beside the reader.
    (repo / 'test' / 'core' / 'bagio').mkdir(parents=True)
    (repo / 'test' / 'core' / 'bagio' / 'test_fastscan.py').write_text('')
    assert len(tool.bag_readers(repo)) == 2


def test_configuration_types_follow_the_naming_rule(tool):
    assert tool.config_type_names(ROOT) == []


def test_a_configuration_type_against_the_rule_is_found(tool, tmp_path):
    repo = _package(
        tmp_path,
        {
            'a.py': (
                'class FitParams:\n    a: float = 1.0\n'
                "class LiveSettings:\n    x: float = setting('trigger', 1.0, 'x')\n"
                "class SensorSettings:\n    f: float = setting('sensor.f', 1.0, 'f')\n"
                "class RunOptions:\n    n: int = setting('run.n', 1, 'n')\n"
                "class Window:\n    s: float = setting('window.s', 1.0, 's')\n"
            ),
        },
    )
    assert [line.split(': ')[1] for line in tool.config_type_names(repo)] == [
        'FitParams',
        'LiveSettings',
        'RunOptions',
        'Window',
    ]


def test_the_floors_and_the_twins_are_held_at_zero(tool):
    assert tool.imports_back_up(ROOT) == []
    assert tool.twins(ROOT) == []


def _floors(tmp_path):
    package = tmp_path / 'lumpbeam_ros'
    layout = {
        '': "__all__ = ['base', 'core', 'nodes', 'apps']\n",
        'base': "__all__ = ['errors']\n",
        'core': "LAYERED = True\n__all__ = ['bagio', 'model']\n",
        'core/bagio': "__all__ = ['reader']\n",
        'core/model': "__all__ = ['chain']\n",
        'nodes': "__all__ = ['node']\n",
        'apps': "LAYERED = True\n__all__ = ['cli']\n",
        'apps/cli': "__all__ = ['main']\n",
    }
    for folder, init in layout.items():
        (package / folder).mkdir(parents=True, exist_ok=True)
        (package / folder / '__init__.py').write_text(init)
    return package


def test_an_import_back_up_is_found(tool, tmp_path):
    package = _floors(tmp_path)
    (package / 'base' / 'errors.py').write_text('import lumpbeam_ros.core.model.chain\n')
    (package / 'core' / 'bagio' / 'reader.py').write_text(
        'def f():\n    from lumpbeam_ros.core.model.chain import Chain\n'
    )
    (package / 'core' / 'model' / 'chain.py').write_text('from lumpbeam_ros.core.bagio import x\n')
    (package / 'nodes' / 'node.py').write_text('from lumpbeam_ros.apps.cli.main import y\n')
    assert tool.imports_back_up(tmp_path) == [
        'lumpbeam_ros.base.errors imports lumpbeam_ros.core.model.chain',
        'lumpbeam_ros.core.bagio.reader imports lumpbeam_ros.core.model.chain',
        'lumpbeam_ros.nodes.node imports lumpbeam_ros.apps.cli.main',
    ]


def test_a_twin_is_found(tool, tmp_path):
    package = tmp_path / 'lumpbeam_ros' / 'nodes'
    package.mkdir(parents=True)
    (package / 'shaper_node.py').write_text(
        'times = [p.time_from_start.sec for p in msg.points]\n'
        "path = config_path('x.yaml') if path is None else Path(path)\n"
    )
    assert [line.split(':')[0] for line in tool.twins(tmp_path)] == [
        'trajectory message conversions',
        'config loaders',
    ]
