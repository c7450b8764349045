"""Lists the core modules that have no test module of their own (test/<pkg>/test_<mod>.py).

Usage: ``python tools/test_modules.py [REPO]``; prints the counts, then one missing module a
line. The core is every package that imports no ROS (doc/architecture.md); the nodes, the CLI,
the demo and the benchmarks are left out.
"""

from __future__ import annotations

import sys
from pathlib import Path

#: The ROS-free core: its packages, and the modules at the top of ``lumpbeam_ros``.
CORE_PACKAGES = (
    'arm',
    'bagio',
    'campaign',
    'compare',
    'diagnose',
    'ident',
    'model',
    'motion',
    'params',
    'plots',
    'report',
    'shaping',
    'synthetic',
    'vision',
    'viz',
)


def core_modules(repo: Path) -> list[Path]:
    """The core's module files, relative to ``repo/lumpbeam_ros`` (no ``__init__.py``)."""
    package = repo / 'lumpbeam_ros'
    files = [p for p in package.glob('*.py')]
    for name in CORE_PACKAGES:
        files += (package / name).rglob('*.py')
    return sorted(p.relative_to(package) for p in files if p.name != '__init__.py')


def mirror_test_path(module: Path) -> Path:
    """Where a module's tests live: ``test/`` mirrors the package."""
    return Path('test', *module.parts[:-1], f'test_{module.stem}.py')


def missing_tests(repo: Path) -> list[Path]:
    """The core modules whose test module does not exist."""
    return [m for m in core_modules(repo) if not (repo / mirror_test_path(m)).is_file()]


def main(argv: list[str]) -> int:
    """Prints the counts and the modules without a test module."""
    repo = Path(argv[1]) if len(argv) > 1 else Path(__file__).resolve().parents[1]
    modules = core_modules(repo)
    missing = missing_tests(repo)
    print(
        f'core modules: {len(modules)}, with a test module: {len(modules) - len(missing)}, '
        f'without: {len(missing)}'
    )
    for module in missing:
        print(f'  lumpbeam_ros/{module.as_posix()}  (no {mirror_test_path(module).as_posix()})')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
