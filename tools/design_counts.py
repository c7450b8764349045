"""Counts that show whether the codebase keeps one way to do each thing.

Usage: ``python tools/design_counts.py [REPO]``. Prints, one line each:

- names of the interface (topics, frames, status and node names) written as string literals
  outside ``lumpbeam_ros/interface.py`` (docstrings and comments do not count; the camera
  frame's name, the word ``'camera'``, also labels the camera among the sensors and is left
  out);
- how nodes get their parameters: ``declare_parameter`` calls outside the one schema-driven
  adapter (``nodes/ros_parameters.py``);
- tip-series types: classes that hold their own ``z: np.ndarray`` column;
- readers that decode ``/tip_pose`` from a bag (``pose_values(`` calls outside the node
  callbacks);
- core modules without a test module (``tools/test_modules.py``).

mypy's count is its own command: ``mypy`` (the configuration is ``mypy.ini``).
"""

from __future__ import annotations

import ast
import importlib.util
import io
import re
import sys
import tokenize
from pathlib import Path


def _load(path: Path, name: str) -> object:
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def interface_names(repo: Path) -> set[str]:
    """The string constants ``lumpbeam_ros/interface.py`` declares (names, not types)."""
    tree = ast.parse((repo / 'lumpbeam_ros' / 'interface.py').read_text())
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Assign | ast.AnnAssign) and isinstance(node.value, ast.Constant):
            value = node.value.value
            if isinstance(value, str) and '/msg/' not in value:
                names.add(value)
    return names - {'camera'}


def _docstring_lines(tree: ast.Module) -> set[int]:
    lines: set[int] = set()
    for node in ast.walk(tree):
        body = getattr(node, 'body', None)
        if isinstance(body, list) and body and isinstance(body[0], ast.Expr):
            value = body[0].value
            if isinstance(value, ast.Constant) and isinstance(value.value, str):
                lines.update(range(value.lineno, (value.end_lineno or value.lineno) + 1))
    return lines


def literal_uses(repo: Path) -> list[str]:
    """``file:line: 'name'`` for each interface name written as a literal outside it."""
    names = interface_names(repo)
    found = []
    for path in sorted((repo / 'lumpbeam_ros').rglob('*.py')):
        if path.name == 'interface.py' and path.parent.name == 'lumpbeam_ros':
            continue
        text = path.read_text()
        skip = _docstring_lines(ast.parse(text))
        for token in tokenize.generate_tokens(io.StringIO(text).readline):
            if token.type != tokenize.STRING or token.start[0] in skip:
                continue
            try:
                value = ast.literal_eval(token.string)
            except (ValueError, SyntaxError):
                continue
            if value in names:
                found.append(f'{path.relative_to(repo)}:{token.start[0]}: {token.string}')
    return found


def _grep(repo: Path, pattern: str, exclude: tuple[str, ...] = ()) -> list[str]:
    regex = re.compile(pattern)
    hits = []
    for path in sorted((repo / 'lumpbeam_ros').rglob('*.py')):
        rel = path.relative_to(repo).as_posix()
        if rel in exclude:
            continue
        for number, line in enumerate(path.read_text().splitlines(), 1):
            if regex.search(line):
                hits.append(f'{rel}:{number}: {line.strip()}')
    return hits


def main(argv: list[str]) -> int:
    """Prints the counts, each with the places that make it up."""
    repo = Path(argv[1]) if len(argv) > 1 else Path(__file__).resolve().parents[1]
    rows = {
        'interface names as literals outside lumpbeam_ros/interface.py': literal_uses(repo),
        'declare_parameter calls outside nodes/ros_parameters.py': _grep(
            repo, r'\.declare_parameters?\(', ('lumpbeam_ros/nodes/ros_parameters.py',)
        ),
        'tip-series types (classes with their own z column)': _grep(repo, r'^    z: np\.ndarray$'),
        'places decoding /tip_pose (the bag reader; nodes on live messages)': _grep(
            repo, r'pose_values\(', ('lumpbeam_ros/bagio/convert.py',)
        ),
    }
    for title, hits in rows.items():
        print(f'{title}: {len(hits)}')
        for hit in hits:
            print(f'  {hit}')
    tests = _load(repo / 'tools' / 'test_modules.py', 'test_modules')
    missing = tests.missing_tests(repo)  # type: ignore[attr-defined]
    print(f'core modules without a test module: {len(missing)} (python tools/test_modules.py)')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
