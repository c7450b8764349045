"""Layers point one way: core <- nodes, core <- demo, core <- cli <- lab (doc/architecture.md).

The product (``lumpbeam_ros``) and the lab that proves it (``lumpbeam_lab``: benchmarks, the
validation renderer, scoring against truth, the MCAP doctor) are separate packages: the lab
may import the product, the product never the lab, except the commands that run it
(``lumpbeam bench``, ``lumpbeam doctor``).

Two checks. Every core module (and every ROS-free module of the lab) is imported in a fresh
interpreter whose import system refuses ROS, the upper layers, the lab and, per package,
OpenCV and matplotlib, so an import that drags one of them in fails here. And the source of
every module of both packages is read for the imports that only run later (inside
functions), so a lazy import of ROS, of an upper layer or of the lab is caught as well.
"""

from __future__ import annotations

import ast
import json
import os
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / 'lumpbeam_ros'
LAB = ROOT / 'lumpbeam_lab'

#: The layers above the core: they may import the core, the core never imports them.
UPPER_LAYERS = ('nodes', 'cli', 'demo')

#: What the core's imports refuse besides libraries: the product's upper layers and the lab.
REFUSED_ABOVE = (*(f'lumpbeam_ros.{layer}' for layer in UPPER_LAYERS), 'lumpbeam_lab')

#: Top-level names of ROS 2: the client library, its middleware and every interface package.
_ROS = re.compile(
    r'^(rclpy|rcl_.*|rmw.*|rosidl.*|ament_.*|launch|launch_ros|tf2.*|message_filters'
    r'|.*_msgs|.*_srvs|.*_interfaces)$'
)

ROS = 'ros'
OPENCV = 'cv2'
MATPLOTLIB = 'matplotlib'

#: What each core package may not need. OpenCV is the image processing of ``vision`` and the
#: renderers of ``synthetic``; matplotlib draws ``plots`` and the figures of ``report``.
#: Everything else (models, identification, diagnosis, bags, parameters, markers) needs
#: numpy and scipy only.
REFUSED: dict[str, frozenset[str]] = {
    'arm': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'bagio': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'campaign': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'compare': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'diagnose': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'ident': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'model': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'motion': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'params': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'shaping': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'viz': frozenset({ROS, OPENCV, MATPLOTLIB}),
    '': frozenset({ROS, OPENCV, MATPLOTLIB}),  # the top-level modules (errors, paramfile, ...)
    'synthetic': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'synthetic.images': frozenset({ROS, MATPLOTLIB}),
    'vision': frozenset({ROS, MATPLOTLIB}),
    # The rig's configuration and the camera model: read by params, viz and the pose-only
    # synthetic drop test, which run without OpenCV.
    'vision.board': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'vision.camera_info_file': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'vision.camera_model': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'vision.config': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'vision.geometry': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'plots': frozenset({ROS, OPENCV}),
    'report': frozenset({ROS, OPENCV}),
}


#: The lab's ROS-free modules, and what each may not need: the ray caster, the validation
#: matrix and the scoring render and track frames with OpenCV; the doctor reads bytes.
LAB_REFUSED: dict[str, frozenset[str]] = {
    'lumpbeam_lab.camera': frozenset({ROS, MATPLOTLIB}),
    'lumpbeam_lab.doctor': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'lumpbeam_lab.mujoco_arm': frozenset({ROS, OPENCV, MATPLOTLIB}),
}


def _modules(package: str) -> list[str]:
    """Dotted names of a core package's modules ('' : the top-level modules)."""
    if package == '':
        return sorted(f'lumpbeam_ros.{p.stem}' for p in PACKAGE.glob('*.py'))
    folder = PACKAGE / package
    names = []
    for path in sorted(folder.rglob('*.py')):
        parts = path.relative_to(PACKAGE).with_suffix('').parts
        if parts[-1] == '__init__':
            parts = parts[:-1]
        names.append('.'.join(('lumpbeam_ros', *parts)))
    return names


def _refusals(module: str) -> frozenset[str]:
    """The most specific entry of :data:`REFUSED` for a module."""
    relative = module.removeprefix('lumpbeam_ros').lstrip('.')
    while relative not in REFUSED:
        relative = relative.rpartition('.')[0] if '.' in relative else ''
    return REFUSED[relative]


def _lab_modules(prefix: str) -> list[str]:
    """Dotted names of the lab's modules under a dotted prefix (a package or a module)."""
    path = ROOT.joinpath(*prefix.split('.'))
    files = sorted(path.rglob('*.py')) if path.is_dir() else [path.with_suffix('.py')]
    return [
        '.'.join(f.relative_to(ROOT).with_suffix('').parts).removesuffix('.__init__')
        for f in files
    ]


#: A group of modules imported together: the libraries and the packages they refuse.
Group = tuple[frozenset[str], tuple[str, ...]]


def _core_groups() -> dict[Group, list[str]]:
    """The core's modules and the lab's ROS-free ones, grouped by what they may not import.

    The core refuses the upper layers and the lab; the lab's ROS-free modules the product's
    upper layers (they need the core only).
    """
    groups: dict[Group, list[str]] = {}
    packages = sorted({key.partition('.')[0] for key in REFUSED})
    for package in packages:
        for module in _modules(package):
            groups.setdefault((_refusals(module), REFUSED_ABOVE), []).append(module)
    upper = tuple(f'lumpbeam_ros.{layer}' for layer in UPPER_LAYERS)
    for prefix, refused in LAB_REFUSED.items():
        groups.setdefault((refused, upper), []).extend(_lab_modules(prefix))
    return groups


_IMPORTER = r"""
import importlib
import importlib.abc
import json
import re
import sys

refused, modules, upper = json.loads(sys.argv[1])
ros = re.compile(sys.argv[2])


def is_refused(name):
    top = name.partition('.')[0]
    if 'ros' in refused and ros.match(top):
        return True
    if top in refused:
        return True
    return any(name == u or name.startswith(f'{u}.') for u in upper)


class Refuse(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path, target=None):
        if is_refused(name):
            raise ModuleNotFoundError(f'refused by the layer test: {name}', name=name)
        return None


already = sorted(n for n in sys.modules if is_refused(n))
sys.meta_path.insert(0, Refuse())
failures = {}
for module in modules:
    try:
        importlib.import_module(module)
    except Exception as exc:
        failures[module] = f'{type(exc).__name__}: {exc}'
print(json.dumps({'already': already, 'failures': failures}))
"""


def _import_refusing(
    refused: frozenset[str], modules: list[str], upper: tuple[str, ...] = REFUSED_ABOVE
) -> dict[str, Any]:
    env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND='Agg')
    argument = json.dumps([sorted(refused), modules, list(upper)])
    done = subprocess.run(
        [sys.executable, '-c', _IMPORTER, argument, _ROS.pattern],
        cwd=ROOT,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.strip().splitlines()[-1])


_GROUPS = _core_groups()


def _group_id(group: Group) -> str:
    lab = '' if 'lumpbeam_lab' in group[1] else 'lab-'
    return lab + 'without-' + '-'.join(sorted(group[0]))


@pytest.mark.parametrize('group', list(_GROUPS), ids=_group_id)
def test_core_imports_without_refused_libraries(group):
    report = _import_refusing(group[0], _GROUPS[group], group[1])
    assert report['already'] == [], 'imported before the test could refuse them'
    assert report['failures'] == {}, '\n'.join(
        f'{m}: {why}' for m, why in report['failures'].items()
    )


@pytest.mark.parametrize(
    ('refused', 'upper', 'module', 'blocked'),
    [
        (frozenset({ROS}), (), 'lumpbeam_ros.nodes.recorder', 'rclpy'),
        (frozenset({OPENCV}), (), 'lumpbeam_ros.vision.detect', 'cv2'),
        (frozenset({MATPLOTLIB}), (), 'lumpbeam_ros.plots.analysis', 'matplotlib'),
        (frozenset(), ('lumpbeam_ros.cli',), 'lumpbeam_ros.cli.output', 'lumpbeam_ros.cli'),
        (frozenset(), ('lumpbeam_lab',), 'lumpbeam_ros.cli.bench', 'lumpbeam_lab'),
    ],
)
def test_the_refusal_catches_what_it_refuses(refused, upper, module, blocked):
    # Modules that do import the refused thing must fail, or the check above proves nothing.
    report = _import_refusing(refused, [module], upper)
    assert module in report['failures']
    assert 'refused by the layer test' in report['failures'][module]
    assert blocked in report['failures'][module]


def _imported_names(path: Path) -> set[str]:
    """Every module a source file imports, at the top or inside functions."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text(encoding='utf-8'))):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module)
    return names


def _layer(module: str) -> str:
    parts = module.split('.')
    if parts[0] == 'lumpbeam_lab':
        return 'lab'
    return parts[1] if len(parts) > 2 and parts[1] in UPPER_LAYERS else 'core'


#: Optional ROS lookups in the core, each behind ``except ImportError``: the share folder
#: of a colcon install is found through ament when it is there.
OPTIONAL_ROS = {'lumpbeam_ros.resources': {'ament_index_python.packages'}}

#: Which layers each layer may import: the core none above it; the nodes and the demo the
#: core (the demo starts nodes as processes, by name); the CLI anything, the lab (for
#: ``lumpbeam bench`` and ``lumpbeam doctor``) included; the lab anything of the product.
ALLOWED = {
    'core': {'core'},
    'nodes': {'core', 'nodes'},
    'demo': {'core', 'demo', 'nodes'},
    'cli': {'core', 'nodes', 'demo', 'cli', 'lab'},
    'lab': {'core', 'nodes', 'demo', 'cli', 'lab'},
}


def _ours(name: str) -> bool:
    return name.partition('.')[0] in {'lumpbeam_ros', 'lumpbeam_lab'}


def _all_modules() -> list[tuple[str, Path]]:
    found = []
    for path in sorted([*PACKAGE.rglob('*.py'), *LAB.rglob('*.py')]):
        parts = path.relative_to(ROOT).with_suffix('').parts
        found.append(('.'.join(parts).removesuffix('.__init__'), path))
    return found


@pytest.mark.parametrize(('module', 'path'), [pytest.param(m, p, id=m) for m, p in _all_modules()])
def test_imports_point_down_the_layers(module, path):
    layer = _layer(module)
    wrong = []
    for name in sorted(_imported_names(path)):
        if _ours(name) and _layer(name) not in ALLOWED[layer]:
            wrong.append(f'{name} ({_layer(name)})')
        optional = name in OPTIONAL_ROS.get(module, set())
        if layer == 'core' and _ROS.match(name.partition('.')[0]) and not optional:
            wrong.append(f'{name} (ROS)')
    assert not wrong, f'{module} ({layer}) imports ' + ', '.join(wrong)


@pytest.mark.parametrize(
    ('module', 'layer'),
    [
        ('lumpbeam_ros.vision.tracker', 'core'),
        ('lumpbeam_ros.nodes.camera_node', 'nodes'),
        ('lumpbeam_ros.cli.bench', 'cli'),
        ('lumpbeam_lab', 'lab'),
        ('lumpbeam_lab.bench.runner', 'lab'),
    ],
)
def test_each_module_is_in_its_layer(module, layer):
    assert _layer(module) == layer


def test_the_core_and_the_lab_are_both_read():
    # The lab's imports are checked too, and the product's core never imports the lab.
    modules = {m for m, _ in _all_modules()}
    assert {'lumpbeam_lab.bench.runner', 'lumpbeam_lab.doctor'} <= modules
    assert 'lab' not in ALLOWED['core'] | ALLOWED['nodes'] | ALLOWED['demo']
    grouped = {m for ms in _GROUPS.values() for m in ms}
    assert {'lumpbeam_lab.doctor', 'lumpbeam_lab.camera.raycast_camera'} <= grouped
