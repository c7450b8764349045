"""The real photographs' calibration files are plain OpenCV's (tools/calibrate_real_photos.py)."""

from __future__ import annotations

import importlib.util
import shutil
from pathlib import Path

import numpy as np
import pytest

from lumpbeam_ros.core.vision.camera_info_file import read_camera_info_file

ROOT = Path(__file__).resolve().parents[1]
PHOTOS = ROOT / 'test' / 'data' / 'real_photos'


def _tool():
    spec = importlib.util.spec_from_file_location(
        'calibrate_real_photos', ROOT / 'tools' / 'calibrate_real_photos.py'
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_committed_calibration_files_are_what_the_tool_writes(tmp_path, capsys):
    for camera in ('left', 'right'):
        shutil.copytree(PHOTOS / camera, tmp_path / camera)
    assert _tool().main(['calibrate_real_photos.py', str(tmp_path)]) == 0
    assert 'left: 13 views' in capsys.readouterr().out
    for camera in ('left', 'right'):
        written = read_camera_info_file(tmp_path / f'{camera}.yaml')
        committed = read_camera_info_file(PHOTOS / f'{camera}.yaml')
        np.testing.assert_allclose(written.k, committed.k, rtol=1e-6)
        np.testing.assert_allclose(written.d, committed.d, rtol=1e-4, atol=1e-6)


@pytest.mark.parametrize('case', ['missing', 'empty', 'too_few', 'not_a_jpeg'])
def test_bad_folders_give_one_line_and_exit_2(tmp_path, capsys, case):
    left, right = tmp_path / 'left', tmp_path / 'right'
    if case != 'missing':
        left.mkdir()
        right.mkdir()
    if case == 'too_few':
        for name in ('left01.jpg', 'left02.jpg'):
            shutil.copy(PHOTOS / 'left' / name, left / name)
    if case == 'not_a_jpeg':
        (left / 'left01.jpg').write_bytes(b'not an image')
    assert _tool().main(['calibrate_real_photos.py', str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count('\n') == 0 and str(left) in err and 'need 3' in err
    assert not (tmp_path / 'left.yaml').exists()
