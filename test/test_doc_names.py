"""Every module, file or function the documentation names exists.

A page names code as a path (``core/bagio/qos.py``, ``lumpbeam_ros/base/``, ``test/...``) or
as a dotted name (``bagio.reader``, ``ident.bag_analysis.analyze_bag``). A path is looked up
from the repository's root and from the package's floors; a dotted name as a module, or a
module and an attribute in it. A page that outlives a rename fails here, not in a reader's
hands.
"""

from __future__ import annotations

import ast
import re
from functools import cache
from pathlib import Path

import pytest

from lumpbeam_ros.base.paramfile import flatten, read_yaml_document
from lumpbeam_ros.nodes.params.reference import SCHEMAS

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / 'lumpbeam_ros'
PAGES = sorted([ROOT / 'README.md', *(ROOT / 'doc').glob('*.md')])

#: Where a path or a dotted name written short is looked up, the repository's root first.
BASES = (ROOT, PACKAGE, PACKAGE / 'core', PACKAGE / 'apps', ROOT / 'lumpbeam_lab')


def _file_keys() -> set[str]:
    """The dotted keys of the shipped files (``synthetic.seed``), ROS 2 parameter files or not."""
    keys = set()
    for path in (ROOT / 'config').glob('*.yaml'):
        keys.update(flatten(read_yaml_document(path)))
    return {key.split('ros__parameters.', 1)[-1] for key in keys}


#: Parameter names (``camera.width_px``) are settings, not code, even where their first word is
#: a package's name.
PARAMETERS = frozenset(
    {spec.name for schema in SCHEMAS for spec in schema.parameters} | _file_keys()
)
#: A dotted span ending in one of these is a file's name (``compare.png``), not a module's.
FILE_ENDINGS = ('png', 'cfg', 'ini', 'txt', 'csv', 'svg', 'html', 'json', 'toml', 'yml', 'py')

#: Code spans: a path of the repository, or a dotted name.
_PATH = re.compile(r'`((?:[a-z_][a-z0-9_]*/)+(?:[a-z_][a-z0-9_]*(?:\.py)?)?)`')
_DOTTED = re.compile(r'`([a-z_][a-z0-9_]*(?:\.[A-Za-z_][A-Za-z0-9_]*)+)`')


@cache
def _roots() -> frozenset[str]:
    """The first words that make a code span a name of ours: folders of the repo and package."""
    names = {p.name for base in BASES for p in base.iterdir() if p.is_dir() or p.suffix == '.py'}
    names |= {p.stem for base in BASES for p in base.glob('*.py')}
    return frozenset(n for n in names if not n.startswith(('.', '_')))


def _path_exists(text: str) -> bool:
    return any((base / text).exists() for base in BASES)


@cache
def _attributes(module: Path) -> frozenset[str]:
    """The names a module defines at its top, and those of its classes (``Class.method``)."""
    tree = ast.parse(module.read_text(encoding='utf-8'))
    names = set()
    for node in tree.body:
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
            names.add(node.name)
            if isinstance(node, ast.ClassDef):
                names.update(
                    f'{node.name}.{item.name}'
                    for item in node.body
                    if isinstance(item, ast.FunctionDef | ast.AsyncFunctionDef)
                )
        elif isinstance(node, ast.Assign | ast.AnnAssign):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            names.update(t.id for t in targets if isinstance(t, ast.Name))
        elif isinstance(node, ast.ImportFrom):
            names.update(alias.asname or alias.name for alias in node.names)
    return frozenset(names)


def _dotted_exists(text: str) -> bool:
    parts = text.split('.')
    for base in BASES:
        for cut in range(len(parts), 0, -1):
            path = base.joinpath(*parts[:cut])
            rest = '.'.join(parts[cut:])
            module = path.with_suffix('.py')
            if module.is_file() and (not rest or rest in _attributes(module)):
                return True
            init = path / '__init__.py'
            if init.is_file() and (not rest or rest in _attributes(init)):
                return True
    return False


def named(text: str) -> list[str]:
    """The paths and dotted names of ours that a page's code spans write."""
    found = []
    for match in _PATH.finditer(text):
        if match.group(1).split('/')[0] in _roots():
            found.append(match.group(1))
    for match in _DOTTED.finditer(text):
        name = match.group(1)
        code = name.split('.')[0] in _roots() and name not in PARAMETERS
        if code and name.rpartition('.')[2] not in (*FILE_ENDINGS, 'md', 'yaml'):
            found.append(name)
    return found


def missing(text: str) -> list[str]:
    """The names of :func:`named` that resolve to nothing."""
    return [
        name
        for name in named(text)
        if not (_path_exists(name) if '/' in name else _dotted_exists(name))
    ]


@pytest.mark.parametrize('page', PAGES, ids=lambda p: p.name)
def test_every_name_a_page_gives_exists(page):
    assert missing(page.read_text(encoding='utf-8')) == []


def test_the_pages_name_code_at_all():
    names = {name for page in PAGES for name in named(page.read_text(encoding='utf-8'))}
    assert len(names) > 50


@pytest.mark.parametrize(
    ('text', 'gone'),
    [
        ('`cli/statics.py` and `core/model/statics.py`', ['cli/statics.py']),
        ('`ident.bag.analyze_bag`, `ident.bag_analysis`', ['ident.bag.analyze_bag']),
        ('`bagio.reader.BagReader.iter_raw`, `bagio.reader.NoSuch`', ['bagio.reader.NoSuch']),
        ('`lumpbeam_ros/base/`, `test/core/model/test_chain.py`', []),
        ('`scipy.signal.fftconvolve`, `window.length_s`', []),
    ],
)
def test_a_name_that_is_gone_is_found(text, gone):
    assert missing(text) == gone
