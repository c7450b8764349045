"""``lumpbeam modes``: the JSON modes list, the payload option, bad input as one line."""

import json
from pathlib import Path

import numpy as np
import pytest

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.core.model.arm.config import load_arm_config
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.statics import arm_modes

CONFIG = Path(__file__).resolve().parents[3] / 'config'
THREE_LINK = str(CONFIG / 'arm_3link.yaml')


def test_writes_every_underdamped_mode_ordered_by_frequency(tmp_path, capsys):
    out = tmp_path / 'modes.json'
    assert main(['modes', '--arm', THREE_LINK, '--q=-0.3,0.5,0.4', '--json', str(out)]) == 0
    assert 'mode 1:' in capsys.readouterr().out
    data = json.loads(out.read_text())
    frequencies = [m['natural_frequency_hz'] for m in data['modes']]
    assert frequencies == sorted(frequencies)
    expected = arm_modes(
        ArmModel.from_config(load_arm_config(THREE_LINK)), np.array([-0.3, 0.5, 0.4])
    )
    assert frequencies == pytest.approx(expected.natural_frequency_hz.tolist(), rel=1e-12)
    assert {tuple(m) for m in data['modes']} == {('natural_frequency_hz', 'damping_ratio')}


def test_a_heavier_payload_lowers_the_first_mode(tmp_path):
    first = []
    for payload in ('0', '5'):
        out = tmp_path / f'{payload}.json'
        argv = ['modes', '--arm', THREE_LINK, '--q=0,0,0', '--payload-kg', payload]
        assert main([*argv, '--json', str(out)]) == 0
        first.append(json.loads(out.read_text())['modes'][0]['natural_frequency_hz'])
    assert first[1] < first[0]


@pytest.mark.parametrize(
    ('argv', 'words'),
    [
        (['--arm', THREE_LINK, '--q=0,0'], 'the arm has 3 joint(s), got 2'),
        (['--arm', THREE_LINK, '--q=0,0,0,0'], 'got 4'),
        (['--arm', THREE_LINK, '--q=0,a,0'], "'a' is not a number"),
        (['--arm', THREE_LINK, '--q=0,nan,0'], 'finite'),
        (['--arm', 'missing.yaml', '--q=0'], 'missing.yaml: no such file'),
    ],
)
def test_bad_input_is_one_line_exit_2(argv, words, capsys):
    assert main(['modes', *argv]) == 2
    err = capsys.readouterr().err
    assert words in err and err.count('\n') == 1


def test_a_bad_file_names_its_key(tmp_path, capsys):
    bad = tmp_path / 'arm.yaml'
    link = '{length_m: 1, n_segments: 2, ei_nm2: 1, mass_kg: 1}'
    bad.write_text(f'arm:\n  plane: sideways\n  links:\n    - {link}\n')
    assert main(['modes', '--arm', str(bad), '--q=0']) == 2
    assert f'{bad}: arm.plane: must be one of vertical, horizontal' in capsys.readouterr().err


def test_a_negative_payload_is_refused_by_the_parser(capsys):
    with pytest.raises(SystemExit) as info:
        main(['modes', '--arm', THREE_LINK, '--q=0,0,0', '--payload-kg', '-1'])
    assert info.value.code == 2
