"""Every package names its public API in ``__all__``, and every name there exists.

A package's face is its ``__all__``: its modules, or the names it re-exports (``core.bagio``'s
``BagReader``). The API reference is built from those faces (``tools/docs_site.py``), and the
floors' order from the top ones (``tools/design_counts.py``).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / 'lumpbeam_ros'
INITS = sorted(PACKAGE.rglob('__init__.py'))


def _faces(init: Path) -> tuple[list[list[str]], set[str]]:
    """Every ``__all__`` the file assigns, and the names it binds at its top."""
    assigned, bound = [], set()
    for node in ast.parse(init.read_text(encoding='utf-8')).body:
        if isinstance(node, ast.Assign | ast.AnnAssign):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            names = {t.id for t in targets if isinstance(t, ast.Name)}
            if '__all__' in names and node.value is not None:
                assigned.append(list(ast.literal_eval(node.value)))
            bound |= names
        elif isinstance(node, ast.ImportFrom):
            bound |= {alias.asname or alias.name for alias in node.names}
        elif isinstance(node, ast.FunctionDef | ast.ClassDef):
            bound.add(node.name)
    return assigned, bound


@pytest.mark.parametrize('init', INITS, ids=lambda p: p.parent.relative_to(PACKAGE).as_posix())
def test_a_package_names_its_public_api_once_and_every_name_exists(init):
    assigned, bound = _faces(init)
    assert len(assigned) == 1, f'{init}: __all__ assigned {len(assigned)} times'
    (names,) = assigned
    assert len(names) == len(set(names)), 'a name twice'
    folder = init.parent
    missing = [
        name
        for name in names
        if name not in bound
        and not (folder / f'{name}.py').is_file()
        and not (folder / name / '__init__.py').is_file()
    ]
    assert missing == []


@pytest.mark.parametrize('init', INITS, ids=lambda p: p.parent.relative_to(PACKAGE).as_posix())
def test_a_package_that_lists_its_modules_lists_every_one(init):
    # A face of re-exported names (core.bagio's BagReader, ...) lists no module; one that
    # lists modules lists them all, so a new module is on the API reference at once.
    (names,), _ = _faces(init)
    folder = init.parent
    modules = {p.stem for p in folder.glob('*.py') if not p.stem.startswith('_')}
    modules |= {p.parent.name for p in folder.glob('*/__init__.py')}
    if modules & set(names):
        assert sorted(modules - set(names)) == []


def test_the_check_sees_a_second_face_and_a_missing_name(tmp_path):
    init = tmp_path / '__init__.py'
    init.write_text("from x import A\n__all__ = ['A']\n__all__ = ['b']\n")
    assigned, bound = _faces(init)
    assert assigned == [['A'], ['b']] and 'A' in bound and 'b' not in bound
