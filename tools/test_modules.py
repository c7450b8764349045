"""Lists the ROS-free modules that have no test module of their own.

Usage: ``python tools/test_modules.py [REPO]``; prints the counts, then one missing module a
line. ``test/`` mirrors the package: ``lumpbeam_ros/core/model/chain.py`` is tested in
``test/core/model/test_chain.py``. The checked modules are those that import no ROS
(doc/architecture.md): the ground floor, the core, the nodes' schemas and the ROS-free
applications; the nodes, the CLI and the demo are left out. The lab (``lumpbeam_lab``) is held
the same way for its ROS-free modules (its top-level modules and :data:`LAB_PACKAGES`),
mirrored under ``test/lab/``; its benchmarks talk to rclpy and are left out like the nodes.
"""

from __future__ import annotations

import sys
from pathlib import Path

#: The ROS-free parts of the product: packages and modules, relative to ``lumpbeam_ros/``.
CORE_PACKAGES = (
    'base',
    'core',
    'nodes/params',
    'nodes/foxglove_server.py',
    'nodes/realtime.py',
    'nodes/ros_domain.py',
    'apps/campaign',
    'apps/json_output.py',
    'apps/plots',
    'apps/report',
)


#: The lab's ROS-free packages (beside its top-level modules): held like the core.
LAB_PACKAGES = ('camera', 'ident')

PRODUCT = 'lumpbeam_ros'
LAB = 'lumpbeam_lab'

#: Each package's checked parts and the folder under ``test/`` that mirrors it.
PACKAGES = {PRODUCT: (CORE_PACKAGES, Path('test')), LAB: (LAB_PACKAGES, Path('test', 'lab'))}


def core_modules(repo: Path, package: str = PRODUCT) -> list[Path]:
    """The checked module files, relative to ``repo/<package>`` (no ``__init__.py``)."""
    folder = repo / package
    files = [p for p in folder.glob('*.py')]
    for name in PACKAGES[package][0]:
        part = folder / name
        files += part.rglob('*.py') if part.is_dir() else [part]
    return sorted(p.relative_to(folder) for p in files if p.name != '__init__.py')


def mirror_test_path(module: Path, package: str = PRODUCT) -> Path:
    """Where a module's tests live: ``test/`` mirrors the product, ``test/lab/`` the lab."""
    return Path(PACKAGES[package][1], *module.parts[:-1], f'test_{module.stem}.py')


def missing_tests(repo: Path, package: str = PRODUCT) -> list[Path]:
    """The checked modules of a package whose test module does not exist."""
    return [
        m
        for m in core_modules(repo, package)
        if not (repo / mirror_test_path(m, package)).is_file()
    ]


def main(argv: list[str]) -> int:
    """Prints the counts and the modules without a test module, for the product and the lab."""
    repo = Path(argv[1]) if len(argv) > 1 else Path(__file__).resolve().parents[1]
    for package, label in ((PRODUCT, 'core'), (LAB, 'lab')):
        modules = core_modules(repo, package)
        missing = missing_tests(repo, package)
        print(
            f'{label} modules: {len(modules)}, with a test module: '
            f'{len(modules) - len(missing)}, without: {len(missing)}'
        )
        for module in missing:
            test = mirror_test_path(module, package).as_posix()
            print(f'  {package}/{module.as_posix()}  (no {test})')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
