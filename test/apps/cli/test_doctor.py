"""``lumpbeam doctor``: clean bags pass, a damaged one is named with its problem."""

from __future__ import annotations

import numpy as np
import pytest

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.core.bagio import BagWriter


def _write_bag(path, n=50):
    with BagWriter(path) as bag:
        bag.add_topic('/tip_load', 'std_msgs/msg/Float64')
        for i in range(n):
            bag.write_float('/tip_load', 1.0 + 0.01 * i, 0.37)
    return path


def test_clean_bags_pass(tmp_path, capsys):
    bags = [_write_bag(tmp_path / name) for name in ('a', 'b')]
    assert main(['doctor', *map(str, bags)]) == 0
    assert capsys.readouterr().out.splitlines() == [f'{bag}: clean' for bag in bags]


def test_a_damaged_file_is_named_with_its_problem(tmp_path, capsys):
    good, bad = _write_bag(tmp_path / 'good'), _write_bag(tmp_path / 'bad')
    (data,) = bad.glob('*.mcap')
    raw = bytearray(data.read_bytes())
    middle = len(raw) // 2
    raw[middle : middle + 64] = np.random.default_rng(1).bytes(64)
    data.write_bytes(bytes(raw))
    assert main(['doctor', str(good), str(bad)]) == 1
    out = capsys.readouterr().out.splitlines()
    assert out[0] == f'{good}: clean'
    assert len(out) > 1 and all(line.startswith(f'{bad}: {data.name}: ') for line in out[1:])


@pytest.mark.parametrize('make', [lambda p: p, lambda p: p.write_text('x') or p])
def test_a_folder_that_is_not_a_bag_is_one_line(tmp_path, capsys, make):
    target = make(tmp_path / 'nothing')
    assert main(['doctor', str(target)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and 'not a bag folder' in err[0], err


def test_an_empty_folder_exits_2(tmp_path, capsys):
    (tmp_path / 'empty').mkdir()
    assert main(['doctor', str(tmp_path / 'empty')]) == 2
    [err] = capsys.readouterr().err.strip().splitlines()
    assert 'not a bag folder' in err
