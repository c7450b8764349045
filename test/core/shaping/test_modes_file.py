"""Modes read from the identification JSON, and every malformed file refused in one line."""

import json

import pytest

from lumpbeam_ros.base.errors import ConfigError
from lumpbeam_ros.core.shaping.impulses import Mode
from lumpbeam_ros.core.shaping.modes_file import read_modes_json


def _write(tmp_path, document):
    path = tmp_path / 'params.json'
    path.write_text(document if isinstance(document, str) else json.dumps(document))
    return path


def test_modes_list_is_taken_whole(tmp_path):
    document = {
        'natural_frequency_hz': 3.2,
        'damping_ratio': 0.01,
        'modes': [
            {'natural_frequency_hz': 3.2, 'damping_ratio': 0.01, 'amplitude_m': 0.02},
            {'natural_frequency_hz': 19.5, 'damping_ratio': 0.03, 'amplitude_m': 0.001},
        ],
    }
    assert read_modes_json(_write(tmp_path, document)) == [Mode(3.2, 0.01), Mode(19.5, 0.03)]


def test_top_level_keys_without_a_modes_list(tmp_path):
    document = {'natural_frequency_hz': 3.2, 'damping_ratio': 0.0105, 'cycles': 20}
    assert read_modes_json(_write(tmp_path, document)) == [Mode(3.2, 0.0105)]


@pytest.mark.parametrize(
    ('document', 'problem'),
    [
        ('{not json', 'not a JSON file'),
        ([1, 2], 'expected a JSON object (the output of lumpbeam analyze)'),
        ({'cycles': 3}, 'has neither a modes list nor natural_frequency_hz'),
        ({'modes': []}, 'modes: expected a non-empty list of modes'),
        (
            {'modes': [3.2]},
            'modes[0]: expected an object with natural_frequency_hz, damping_ratio',
        ),
        (
            {'natural_frequency_hz': None, 'damping_ratio': 0.01},
            'natural_frequency_hz: missing or null (no estimate)',
        ),
        (
            {
                'modes': [
                    {'natural_frequency_hz': 3.0, 'damping_ratio': 0.01},
                    {'damping_ratio': 0},
                ]
            },
            'modes[1].natural_frequency_hz: missing or null (no estimate)',
        ),
        (
            {'modes': [{'natural_frequency_hz': '3', 'damping_ratio': 0.01}]},
            "modes[0].natural_frequency_hz: not a number: '3'",
        ),
        (
            {'modes': [{'natural_frequency_hz': 3.0, 'damping_ratio': True}]},
            'modes[0].damping_ratio: not a number: True',
        ),
        (
            '{"natural_frequency_hz": NaN, "damping_ratio": 0.01}',
            'natural_frequency_hz: not finite: nan',
        ),
        (
            {'natural_frequency_hz': -3.0, 'damping_ratio': 0.01},
            'natural_frequency_hz: natural frequency must be a positive number of Hz, got -3.0',
        ),
        (
            {'modes': [{'natural_frequency_hz': 3.0, 'damping_ratio': 1.2}]},
            'modes[0]: damping ratio must be in [0, 1) (an underdamped mode), got 1.2',
        ),
    ],
)
def test_bad_files_are_one_line(tmp_path, document, problem):
    path = _write(tmp_path, document)
    with pytest.raises(ConfigError) as caught:
        read_modes_json(path)
    assert str(caught.value) == f'{path}: {problem}'


@pytest.mark.parametrize(
    ('name', 'problem'),
    [('missing.json', 'no such file'), ('x' * 300, 'cannot read it (File name too long)')],
)
def test_unreadable_files_are_one_line(tmp_path, name, problem):
    with pytest.raises(ConfigError) as caught:
        read_modes_json(tmp_path / name)
    assert str(caught.value) == f'{tmp_path / name}: {problem}'
