"""Imports point down the floors, and down the core's packages (doc/architecture.md).

The floors are ``lumpbeam_ros.__all__`` (base, core, nodes, apps), bottom first; the core's
packages and the applications are ordered the same way by their own ``__all__``. A module
may import its own floor and the floors below; inside ``core`` and ``apps``, its own package
and those listed before it. The lab that proves the product (``lumpbeam_lab``: benchmarks,
the validation renderer, scoring against truth, MuJoCo's arm) is not installed with it and
stands above everything: it may import the product, the product never imports it (``lumpbeam
bench`` finds it in the checkout at run time).

Two checks. Every ROS-free module (the ground floor, the core, the nodes' schemas, the
campaign and the figures, and the lab's ROS-free modules) is imported in a fresh interpreter
whose import system refuses ROS, the floors above it, the lab and, per package, OpenCV and
matplotlib, so an import that drags one of them in fails here. And the source of every
module of both packages is read for its imports, those inside functions included, so a lazy
import that runs back up is caught as well.
"""

from __future__ import annotations

import importlib.util
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


def _design_counts():
    spec = importlib.util.spec_from_file_location(
        'design_counts', ROOT / 'tools' / 'design_counts.py'
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


#: The rule, declared once (``tools/design_counts.py``, which counts what breaks it).
_TOOL = _design_counts()
_FLOORS = _TOOL.Floors(ROOT)
may_import = _FLOORS.may_import


#: Top-level names of ROS 2: the client library, its middleware and every interface package.
_ROS = re.compile(
    r'^(rclpy|rcl_.*|rmw.*|rosidl.*|ament_.*|launch|launch_ros|tf2.*|message_filters'
    r'|.*_msgs|.*_srvs|.*_interfaces)$'
)

ROS = 'ros'
OPENCV = 'cv2'
MATPLOTLIB = 'matplotlib'

#: What each ROS-free package may not need (the most specific entry holds). OpenCV is the
#: image processing of ``vision`` and the renderers of ``synthetic``; matplotlib draws
#: ``plots`` and the figures of ``report``. Everything else (models, identification,
#: diagnosis, bags, parameters, markers) needs numpy and scipy only.
REFUSED: dict[str, frozenset[str]] = {
    'base': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'core': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'core.synthetic.images': frozenset({ROS, MATPLOTLIB}),
    'core.vision': frozenset({ROS, MATPLOTLIB}),
    # The rig's configuration and the camera model: read by the nodes' schemas, viz and the
    # pose-only synthetic drop test, which run without OpenCV.
    'core.vision.board': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'core.vision.camera_info_file': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'core.vision.camera_model': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'core.vision.config': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'core.vision.geometry': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'core.vision.placement': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'nodes.params': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'nodes.realtime': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'nodes.ros_domain': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'nodes.foxglove_server': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'apps.json_output': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'apps.campaign': frozenset({ROS, OPENCV, MATPLOTLIB}),
    'apps.plots': frozenset({ROS, OPENCV}),
    'apps.report': frozenset({ROS, OPENCV}),
}


#: The lab's ROS-free modules, and what each may not need: the ray caster, the validation
#: matrix and the scoring render and track frames with OpenCV.
LAB_REFUSED: dict[str, frozenset[str]] = {
    'lumpbeam_lab.camera': frozenset({ROS, MATPLOTLIB}),
    'lumpbeam_lab.mujoco_arm': frozenset({ROS, OPENCV, MATPLOTLIB}),
}


def _modules(package: str) -> list[str]:
    """Dotted names of a package's modules, or of one module (relative to the product)."""
    path = PACKAGE.joinpath(*package.split('.'))
    files = sorted(path.rglob('*.py')) if path.is_dir() else [path.with_suffix('.py')]
    return [
        '.'.join(f.relative_to(ROOT).with_suffix('').parts).removesuffix('.__init__')
        for f in files
    ]


def _refusals(module: str) -> frozenset[str]:
    """The most specific entry of :data:`REFUSED` for a module."""
    relative = module.removeprefix('lumpbeam_ros.')
    while relative not in REFUSED:
        relative = relative.rpartition('.')[0]
    return REFUSED[relative]


def _above(module: str) -> tuple[str, ...]:
    """What a module may not import: the floors above its own, and the lab."""
    floor = module.split('.')[1]
    above = _FLOORS.floors[_FLOORS.floors.index(floor) + 1 :]
    return (*(f'lumpbeam_ros.{name}' for name in above), 'lumpbeam_lab')


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
    """The ROS-free modules of both packages, grouped by what they may not import."""
    groups: dict[Group, list[str]] = {}
    for module in sorted({m for key in REFUSED for m in _modules(key)}):
        groups.setdefault((_refusals(module), _above(module)), []).append(module)
    upper = tuple(
        f'lumpbeam_ros.{name}' for name in _FLOORS.floors[_FLOORS.floors.index('nodes') :]
    )
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
    refused: frozenset[str], modules: list[str], upper: tuple[str, ...]
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
    floors = '-'.join(n.rpartition('.')[2] for n in group[1] if n.startswith('lumpbeam_ros'))
    return f'{lab}without-' + '-'.join(sorted(group[0])) + f'-below-{floors}'


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
        (frozenset({OPENCV}), (), 'lumpbeam_ros.core.vision.detect', 'cv2'),
        (frozenset({MATPLOTLIB}), (), 'lumpbeam_ros.apps.plots.analysis', 'matplotlib'),
        (
            frozenset(),
            ('lumpbeam_ros.apps.cli',),
            'lumpbeam_ros.apps.cli.output',
            'lumpbeam_ros.apps.cli',
        ),
    ],
)
def test_the_refusal_catches_what_it_refuses(refused, upper, module, blocked):
    # Modules that do import the refused thing must fail, or the check above proves nothing.
    report = _import_refusing(refused, [module], upper)
    assert module in report['failures']
    assert 'refused by the layer test' in report['failures'][module]
    assert blocked in report['failures'][module]


_imported_names = _TOOL.imported_names


#: Optional ROS lookups on the ground floor, each behind ``except ImportError``: the share
#: folder of a colcon install is found through ament when it is there.
OPTIONAL_ROS = {'lumpbeam_ros.base.resources': {'ament_index_python.packages'}}

#: The floors that never import ROS.
ROS_FREE = ('base', 'core')


def _ours(name: str) -> bool:
    return name.partition('.')[0] in {'lumpbeam_ros', 'lumpbeam_lab'}


def _all_modules() -> list[tuple[str, Path]]:
    found = []
    for path in sorted([*PACKAGE.rglob('*.py'), *LAB.rglob('*.py')]):
        parts = path.relative_to(ROOT).with_suffix('').parts
        found.append(('.'.join(parts).removesuffix('.__init__'), path))
    return found


@pytest.mark.parametrize(('module', 'path'), [pytest.param(m, p, id=m) for m, p in _all_modules()])
def test_imports_point_down(module, path):
    wrong = []
    for name in sorted(_imported_names(path)):
        if _ours(name) and name != 'lumpbeam_ros' and not may_import(module, name):
            wrong.append(name)
        optional = name in OPTIONAL_ROS.get(module, set())
        floor = module.split('.')[1] if module.startswith('lumpbeam_ros.') else ''
        if floor in ROS_FREE and _ROS.match(name.partition('.')[0]) and not optional:
            wrong.append(f'{name} (ROS)')
    assert not wrong, f'{module} imports ' + ', '.join(wrong)


@pytest.mark.parametrize(
    ('module', 'name', 'allowed'),
    [
        ('lumpbeam_ros.core.vision.tracker', 'lumpbeam_ros.core.bagio.reader', True),
        ('lumpbeam_ros.core.bagio.reader', 'lumpbeam_ros.core.model.chain', False),
        ('lumpbeam_ros.core.model.chain', 'lumpbeam_ros.core.ident.pencil', False),
        ('lumpbeam_ros.core.ident.pencil', 'lumpbeam_ros.core.model.chain', True),
        ('lumpbeam_ros.base.schema', 'lumpbeam_ros.core.model.chain', False),
        ('lumpbeam_ros.nodes.params.camera_params', 'lumpbeam_ros.core.vision.config', True),
        ('lumpbeam_ros.nodes.camera_node', 'lumpbeam_ros.apps.cli.main', False),
        ('lumpbeam_ros.apps.plots.beam', 'lumpbeam_ros.apps.cli.main', False),
        ('lumpbeam_ros.apps.cli.main', 'lumpbeam_ros.apps.demo.graph', True),
        ('lumpbeam_ros.apps.cli.bench', 'lumpbeam_lab.bench.runner', False),
        ('lumpbeam_lab.bench.runner', 'lumpbeam_ros.apps.cli.main', True),
    ],
)
def test_the_order_allows_down_and_refuses_up(module, name, allowed):
    assert may_import(module, name) is allowed


def test_every_floor_and_package_is_ranked():
    # A package left out of its floor's __all__ would rank as the bottom of its floor.
    found = {p.name for p in PACKAGE.iterdir() if (p / '__init__.py').is_file()}
    assert set(_FLOORS.floors) == found
    for floor, order in _FLOORS.ordered.items():
        inside = {p.stem for p in (PACKAGE / floor).glob('*.py') if p.stem != '__init__'}
        inside |= {p.parent.name for p in (PACKAGE / floor).glob('*/__init__.py')}
        assert set(order) == inside, floor


def test_the_product_and_the_lab_are_both_read():
    # The lab's imports are checked too, and the lab is read by the import check.
    modules = {m for m, _ in _all_modules()}
    assert {'lumpbeam_lab.bench.runner', 'lumpbeam_ros.core.bagio.reader'} <= modules
    grouped = {m for ms in _GROUPS.values() for m in ms}
    assert {'lumpbeam_lab.camera.raycast_camera', 'lumpbeam_ros.base.schema'} <= grouped
