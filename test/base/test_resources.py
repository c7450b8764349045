import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest
import yaml

from lumpbeam_ros.base.resources import PACKAGE, config_path, large_frames_profile

ROOT = Path(__file__).resolve().parents[2]
FASTDDS = '{http://www.eprosima.com/XMLSchemas/fastRTPS_Profiles}'
#: A file name that no layout but the one under test holds.
ONLY_HERE = 'only_in_this_layout.yaml'


@pytest.mark.parametrize(
    'name', sorted(p.name for p in (ROOT / 'config').iterdir() if p.suffix == '.yaml')
)
def test_every_default_config_is_found_in_the_checkout(name):
    path = config_path(name)
    assert path == ROOT / 'config' / name
    assert isinstance(yaml.safe_load(path.read_text()), dict)


@pytest.mark.parametrize('name', [ONLY_HERE, 'paper_beam.yml', 'config/paper_beam.yaml'])
def test_a_config_that_is_not_installed_is_a_clear_error(name):
    with pytest.raises(
        FileNotFoundError, match=f"{PACKAGE}: default config '.*' is not installed"
    ):
        config_path(name)


def _install_config(prefix: Path) -> Path:
    """A prefix laid out as ``pip install`` and colcon leave it (setup.py's data_files)."""
    (prefix / 'share' / 'ament_index' / 'resource_index' / 'packages').mkdir(parents=True)
    (prefix / 'share' / 'ament_index' / 'resource_index' / 'packages' / PACKAGE).write_text('')
    config = prefix / 'share' / PACKAGE / 'config'
    config.mkdir(parents=True)
    (config / ONLY_HERE).write_text('a: 1\n')
    return config / ONLY_HERE


def test_an_ament_install_is_found_through_its_index(tmp_path, monkeypatch):
    installed = _install_config(tmp_path / 'install')
    monkeypatch.setenv('AMENT_PREFIX_PATH', str(tmp_path / 'install'))
    assert config_path(ONLY_HERE) == installed
    # The checkout comes first: its own files win over an older install.
    assert config_path('paper_beam.yaml') == ROOT / 'config' / 'paper_beam.yaml'


def test_a_pip_install_is_found_under_the_interpreter_prefix(tmp_path, monkeypatch):
    installed = _install_config(tmp_path / 'venv')
    monkeypatch.delenv('AMENT_PREFIX_PATH', raising=False)
    monkeypatch.setattr(sys, 'prefix', str(tmp_path / 'venv'))
    assert config_path(ONLY_HERE) == installed


def test_an_unset_or_foreign_ament_path_is_skipped(tmp_path, monkeypatch):
    monkeypatch.setenv('AMENT_PREFIX_PATH', str(tmp_path / 'nothing_here'))
    assert config_path('camera.yaml') == ROOT / 'config' / 'camera.yaml'
    with pytest.raises(FileNotFoundError):
        config_path(ONLY_HERE)


def test_the_large_frames_profile_gives_whole_frames_room():
    path = large_frames_profile()
    assert path.is_file() and path.parent.name == 'data'
    root = ET.parse(path).getroot()
    assert root.tag == f'{FASTDDS}profiles'
    segments = [int(e.text) for e in root.iter(f'{FASTDDS}segment_size')]
    # A 1 MB frame (1280 x 800 mono8) and then some: the default segment is 512 KiB.
    assert segments and min(segments) >= 4 * 1280 * 800
    default = [p for p in root.iter(f'{FASTDDS}participant') if p.get('is_default_profile')]
    assert len(default) == 1
    used = {e.text for e in default[0].iter(f'{FASTDDS}transport_id')}
    declared = {e.text for e in root.iter(f'{FASTDDS}transport_id')} - used
    assert 'shm_large' in used and not declared  # every transport declared is used


def test_a_packaged_file_is_found_by_its_repository_path_from_anywhere(tmp_path, monkeypatch):
    from lumpbeam_ros.base.resources import packaged, share_dir

    monkeypatch.chdir(tmp_path)
    assert packaged('config/arm_3link.yaml') == share_dir() / 'config' / 'arm_3link.yaml'
    assert packaged('examples/two_joint_move.csv').is_file()
    # A file where the user runs wins; an absolute path and a missing one stay as given.
    (tmp_path / 'config').mkdir()
    (tmp_path / 'config' / 'arm_3link.yaml').write_text('mine')
    assert packaged('config/arm_3link.yaml') == Path('config/arm_3link.yaml')
    assert packaged(tmp_path / 'no.yaml') == tmp_path / 'no.yaml'
    assert packaged('config/no_such.yaml') == Path('config/no_such.yaml')
