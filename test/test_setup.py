"""The package builds as an ament_python package with colcon, as a ROS 2 workspace builds it.

Debian's ``colcon`` and ``python3-colcon-ros`` (``.ci/run`` installs them) build a copy of
the repository's files in a fresh workspace; the install space must hold every console
script that ``setup.py`` declares, the package's data and its shared configuration files.
"""

import importlib.metadata
import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = 'lumpbeam_ros'


def _declared_scripts() -> set[str]:
    """The console scripts of the installed distribution (setup.py's entry points)."""
    entry_points = importlib.metadata.distribution(PACKAGE).entry_points
    return {ep.name for ep in entry_points if ep.group == 'console_scripts'}


def _copy_repository(dest: Path) -> None:
    listed = subprocess.run(
        ['git', 'ls-files', '-co', '--exclude-standard'],
        cwd=ROOT,
        capture_output=True,
        text=True,
        check=True,
    ).stdout.splitlines()
    for name in listed:
        source = ROOT / name
        if source.is_file():
            (dest / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, dest / name)


@pytest.fixture(scope='module')
def install_space(tmp_path_factory):
    colcon = shutil.which('colcon')
    missing = 'colcon missing (apt-get install colcon python3-colcon-ros)'
    # CI installs colcon (.ci/run): there its absence is a failure, not a skip. A developer's
    # machine without it skips the build and says why.
    if colcon is None and os.environ.get('CI'):
        pytest.fail(missing)
    if colcon is None:
        pytest.skip(missing)
    workspace = tmp_path_factory.mktemp('ws')
    _copy_repository(workspace / 'src' / PACKAGE)
    built = subprocess.run(
        [colcon, 'build', '--event-handlers', 'console_direct-'],
        cwd=workspace,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert built.returncode == 0, built.stdout[-2000:] + built.stderr[-2000:]
    return workspace / 'install' / PACKAGE


def test_colcon_installs_every_console_script(install_space):
    scripts = {p.name for p in (install_space / 'lib' / PACKAGE).iterdir()}
    assert _declared_scripts() <= scripts
    # They run with the python3 on PATH (a venv holding ROS from pip), not colcon's own.
    for name in _declared_scripts():
        first = (install_space / 'lib' / PACKAGE / name).read_text().splitlines()[0]
        assert first == '#!/usr/bin/env python3', name
    assert {'camera_node', 'identifier_node', 'simulator_node', 'lumpbeam'} <= scripts


def test_colcon_installs_the_package_index_configs_and_data(install_space):
    share = install_space / 'share'
    assert (share / 'ament_index' / 'resource_index' / 'packages' / PACKAGE).is_file()
    assert (share / PACKAGE / 'package.xml').is_file()
    shipped = {p.name for p in (share / PACKAGE / 'config').iterdir()}
    assert {p.name for p in (ROOT / 'config').iterdir()} <= shipped
    launch = {p.name for p in (share / PACKAGE / 'launch').iterdir()}
    assert {p.name for p in (ROOT / 'launch').glob('*.launch.yaml')} <= launch
    examples = {p.name for p in (share / PACKAGE / 'examples').iterdir()}
    assert {p.name for p in (ROOT / 'examples').glob('*.csv')} <= examples
    (site,) = (install_space / 'lib').glob('python3*/site-packages')
    data = {p.name for p in (site / PACKAGE / 'base' / 'data').iterdir()}
    assert {p.name for p in (ROOT / PACKAGE / 'base' / 'data').iterdir()} <= data
    # The product alone: what proves it stays in the repository.
    assert (site / PACKAGE / 'core' / 'model' / 'arm' / 'simulate.py').is_file()
    assert not (site / 'lumpbeam_lab').exists()


def test_the_distribution_carries_the_readme():
    metadata = importlib.metadata.metadata(PACKAGE)
    assert metadata['Description-Content-Type'] == 'text/markdown'
    assert (ROOT / 'README.md').read_text(encoding='utf-8').splitlines()[0] in (
        metadata.get_payload() or metadata['Description']
    )


def test_opencv_is_within_the_declared_range():
    """Run on the venv's OpenCV (the newest) and on the lowest (``make test-opencv-lowest``)."""
    import cv2
    from packaging.requirements import Requirement

    declared = [Requirement(r) for r in importlib.metadata.requires(PACKAGE) or []]
    ranges = {r.specifier for r in declared if r.name == 'opencv-python-headless'}
    assert len(ranges) == 1  # [vision] and [all] alike
    assert cv2.__version__ in ranges.pop(), cv2.__version__
