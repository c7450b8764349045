import json
import math

import numpy as np
import pytest

from lumpbeam_ros.apps.json_output import plain_json, write_json
from lumpbeam_ros.base.errors import LumpbeamError


@pytest.mark.parametrize(
    ('value', 'plain'),
    [
        (np.float64(0.25), 0.25),
        (np.int32(7), 7),
        (np.bool_(True), True),
        (np.array([[1.5, np.nan], [np.inf, -2.0]]), [[1.5, None], [None, -2.0]]),
        (math.nan, None),
        (-math.inf, None),
        ((1, np.float32(0.5)), [1, 0.5]),
        ({1: {'k': np.arange(3)}}, {'1': {'k': [0, 1, 2]}}),
        ('text', 'text'),
        (None, None),
    ],
)
def test_plain_json_gives_strict_json_values(value, plain):
    result = plain_json(value)
    assert result == plain
    # Strict JSON: no NaN or Infinity token, and numpy types are gone.
    json.dumps(result, allow_nan=False)
    assert type(json.loads(json.dumps(result))) is type(plain)


def test_write_json_round_trips_and_creates_the_folder(tmp_path):
    path = tmp_path / 'new' / 'result.json'
    write_json(path, {'f_hz': np.float64(3.0588), 'bad': np.nan, 'n': np.int64(901)})
    assert json.loads(path.read_text(encoding='utf-8')) == {
        'f_hz': 3.0588,
        'bad': None,
        'n': 901,
    }


def test_write_json_names_a_path_it_cannot_write(tmp_path):
    blocker = tmp_path / 'file'
    blocker.write_text('x')
    with pytest.raises(LumpbeamError, match=r'cannot write JSON to .*file/out\.json'):
        write_json(blocker / 'out.json', {'a': 1})


def test_a_messages_values_are_written_as_numbers_where_they_are_numbers():
    from lumpbeam_ros.apps.json_output import typed_values

    values = {'mode_count': '2', 'natural_frequency_hz': '1.79', 'std': 'nan', 'status': 'OK'}
    assert typed_values(values) == {
        'mode_count': 2,
        'natural_frequency_hz': 1.79,
        'std': None,
        'status': 'OK',
    }
