import json

from lumpbeam_ros.apps.cli.main import main


def test_json_has_the_spec_keys(tmp_path, capsys):
    out = tmp_path / 'r.json'
    assert main(['reproduce', '--json', str(out)]) == 0
    printed = capsys.readouterr().out
    assert '65 of 65 numbers within tolerance' in printed
    data = json.loads(out.read_text())
    assert [row['n_s'] for row in data['table_b1']] == list(range(1, 11))
    assert set(data['table_b2'][0]) == {'n_s', 'uniform_m', 'loaded_m', 'end_load_m'}
    assert set(data['frequencies_hz']) == {'analytic', 'identified', 'validation'}
    assert set(data['static_6p5kg_m']) == {'model', 'analytic'}


def test_unwritable_json_is_one_line(tmp_path, capsys):
    blocker = tmp_path / 'file'
    blocker.write_text('')
    assert main(['reproduce', '--json', str(blocker / 'r.json')]) == 2
    err = capsys.readouterr().err
    assert err.startswith('lumpbeam reproduce: error: cannot write JSON')
