import argparse
import json

import numpy as np
import pytest

from lumpbeam_ros.apps.cli.output import non_negative_float, positive_float, write_json


@pytest.mark.parametrize('text', ['0', '-1', 'nan', 'inf', 'abc', ''])
def test_positive_float_refuses(text):
    with pytest.raises(argparse.ArgumentTypeError):
        positive_float(text)


@pytest.mark.parametrize('text', ['-1e-9', 'nan', '-inf', 'x'])
def test_non_negative_float_refuses(text):
    with pytest.raises(argparse.ArgumentTypeError):
        non_negative_float(text)


def test_accepted_values():
    assert positive_float('2.5') == 2.5
    assert non_negative_float('0') == 0.0


def test_json_turns_numpy_and_nan_into_plain_values(tmp_path):
    path = tmp_path / 'a' / 'b.json'
    write_json(path, {'x': np.float64(1.5), 'v': np.arange(3), 'bad': float('nan')})
    assert json.loads(path.read_text()) == {'x': 1.5, 'v': [0, 1, 2], 'bad': None}
