import json
import math
import re
import shutil
from dataclasses import replace

import numpy as np
import pytest

from lumpbeam_ros.apps.campaign.bags import fingerprint
from lumpbeam_ros.apps.campaign.task import (
    ID_COLUMNS,
    SCHEMA_VERSION,
    CampaignOptions,
    error_line,
    flatten,
    process_bag,
    row_key,
)
from lumpbeam_ros.base.errors import BagError, LumpbeamError
from lumpbeam_ros.core.ident.bag_analysis import analyze_bag, result_json
from lumpbeam_ros.core.ident.settings import load_identifier_config
from lumpbeam_ros.core.model.chain import LumpedChain
from lumpbeam_ros.core.model.modes import chain_modes
from lumpbeam_ros.core.model.parameters import load_beam_config

from .conftest import LOADS, truncate_bag


def _strict_json(text):
    """Parses JSON as the standard has it: NaN and Infinity are not JSON."""

    def refuse(name):
        raise ValueError(f'{name} is not JSON')

    return json.loads(text, parse_constant=refuse)


@pytest.fixture(scope='module')
def settings():
    beam, _ = load_beam_config()
    return CampaignOptions(beam, load_identifier_config())


# -- flatten ---------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ('data', 'expected'),
    [
        ({}, {}),
        ({'a': 1, 'b': 'x', 'c': None, 'd': True}, {'a': 1, 'b': 'x', 'c': None, 'd': True}),
        ({'gap': {'rms_m': 1e-4, 'peak': {'t_s': 2.0}}}, {'gap.rms_m': 1e-4, 'gap.peak.t_s': 2.0}),
        ({'f': [3.05, 19.1]}, {'f': '[3.05, 19.1]'}),
        ({'f': (1, 2)}, {'f': '[1, 2]'}),
        ({'nan': math.nan, 'inf': -math.inf}, {'nan': None, 'inf': None}),
        ({'n': np.float64(2.5), 'k': np.int64(3)}, {'n': 2.5, 'k': 3}),
        ({'n': np.float32(math.nan)}, {'n': None}),
        ({'f': [1.0, math.nan, math.inf]}, {'f': '[1.0, null, null]'}),
        ({'f': [np.float64(math.nan), np.int64(4)]}, {'f': '[null, 4]'}),
        ({'f': [[1.0, math.nan], {'std': -math.inf}]}, {'f': '[[1.0, null], {"std": null}]'}),
        ({'f': np.array([1.0, math.nan])}, {'f': '[1.0, null]'}),
    ],
    ids=[
        'empty',
        'scalars',
        'nested',
        'list',
        'tuple',
        'non-finite',
        'numpy scalars',
        'numpy NaN',
        'NaN in a list',
        'numpy in a list',
        'nested lists',
        'numpy array',
    ],
)
def test_flatten(data, expected):
    row = flatten(data)
    assert row == expected
    for value in row.values():
        assert value is None or type(value) in (bool, int, float, str)
        if isinstance(value, str) and value.startswith('['):
            _strict_json(value)  # lists are valid JSON text


def test_flatten_prefixes_every_column():
    assert flatten({'a': {'b': 1}, 'c': 2}, 'diag.') == {'diag.a.b': 1, 'diag.c': 2}


# -- settings and keys -----------------------------------------------------------------------


def test_the_settings_digest_is_stable_and_names_every_setting(settings):
    digest = settings.digest()
    assert re.fullmatch('[0-9a-f]{16}', digest)
    assert CampaignOptions(settings.beam, settings.identifier).digest() == digest
    changed = [
        replace(settings, diagnose=True),
        replace(settings, beam=replace(settings.beam, length_m=settings.beam.length_m * 1.01)),
        replace(settings, identifier=replace(settings.identifier, min_frequency_hz=0.7)),
    ]
    digests = {c.digest() for c in changed}
    assert len(digests) == len(changed) and digest not in digests


def test_row_keys_tell_path_content_and_settings_apart():
    key = row_key('/bags/a', 'c1', 's1')
    assert re.fullmatch('[0-9a-f]{32}', key) and row_key('/bags/a', 'c1', 's1') == key
    others = [
        row_key('/bags/b', 'c1', 's1'),
        row_key('/bags/a', 'c2', 's1'),
        row_key('/bags/a', 'c1', 's2'),
        row_key('/bags/ac', '1', 's1'),  # the fields are separated, not just joined
    ]
    assert len({key, *others}) == 5


# -- error_line ------------------------------------------------------------------------------


AT_THIS_FILE = r'\(at test_task.py:\d+\)'


def _raised(exc):
    try:
        raise exc
    except BaseException as caught:  # noqa: BLE001
        return caught


@pytest.mark.parametrize(
    ('exc', 'expected'),
    [
        (BagError('/b: no topic /tip_pose\nmore detail'), '/b: no topic /tip_pose'),
        (LumpbeamError(''), 'LumpbeamError'),
        (ValueError('x must be positive'), rf'ValueError: x must be positive {AT_THIS_FILE}'),
        (ZeroDivisionError(), rf'ZeroDivisionError:  {AT_THIS_FILE}'),
    ],
)
def test_error_line(exc, expected):
    line = error_line(_raised(exc))
    assert re.fullmatch(expected, line) and '\n' not in line


def test_an_error_never_raised_names_no_place():
    assert error_line(KeyError('k')) == "KeyError: 'k'"


# -- process_bag -----------------------------------------------------------------------------


def test_a_bag_becomes_one_row_of_its_results(campaign_bags, settings):
    bag = campaign_bags[1]
    row = process_bag(str(bag), settings)
    assert set(ID_COLUMNS) <= set(row)
    assert row['error'] == '' and row['schema_version'] == SCHEMA_VERSION
    assert row['content_hash'] == fingerprint(bag)
    assert row['key'] == row_key(str(bag), row['content_hash'], settings.digest())
    assert row['load_kg'] == pytest.approx(LOADS[1])  # the load the bag was written with
    assert row['pose_count'] == 901 and row['diagnosed'] is False
    result = analyze_bag(bag, settings.beam, settings.identifier, show_progress=False).result
    for key, value in result_json(result).items():
        if isinstance(value, float):
            assert row[key] == (value if math.isfinite(value) else None), key
    # The first mode of the model the bag was simulated with (linearised: 1e-4 of it).
    truth = chain_modes(LumpedChain.from_beam(settings.beam, 0.0)).natural_frequency_hz[0]
    assert row['natural_frequency_hz'] == pytest.approx(truth, rel=1e-4)
    assert row['natural_frequency_hz_std'] > 0
    json.dumps(row, allow_nan=False)  # every value a JSON scalar


@pytest.mark.slow  # the diagnosis simulates every candidate: ~10 s
def test_a_diagnosed_row_holds_the_diagnosis(campaign_bags, settings):
    row = process_bag(str(campaign_bags[0]), replace(settings, diagnose=True))
    assert row['error'] == '' and row['diagnosed'] is True
    assert isinstance(row['missing_effect'], str) and row['gap_before.rms_m'] >= 0
    candidates = _strict_json(row['candidates'])  # scores may be inf: written as null
    assert candidates and all({'name', 'parameters', 'score'} <= set(c) for c in candidates)
    json.dumps(row, allow_nan=False)


def test_a_bad_bag_is_a_row_with_its_error(tmp_path, campaign_bags, settings):
    missing = process_bag(str(tmp_path / 'missing'), settings)
    assert 'no such bag' in missing['error'] and missing['content_hash'] == ''
    assert missing['key'] == row_key(str(tmp_path / 'missing'), '', settings.digest())
    cut = tmp_path / 'cut'
    shutil.copytree(campaign_bags[0], cut)
    truncate_bag(cut, 0.4)
    row = process_bag(str(cut), settings)
    assert row['error'] and '\n' not in row['error'] and row['content_hash']
    assert row.get('natural_frequency_hz') is None
