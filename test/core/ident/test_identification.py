import dataclasses
import json
import math
from pathlib import Path

import pytest

from lumpbeam_ros.apps.cli.analyze import CONTRACT_KEYS
from lumpbeam_ros.core.bagio.tipseries import SampleCounts
from lumpbeam_ros.core.ident.identification import (
    Estimate,
    Estimates,
    Identification,
    IdentifiedMode,
    ReleaseFigures,
    Status,
)
from lumpbeam_ros.core.shaping.estimate import estimate_from_status

GOLDEN = json.loads((Path(__file__).parents[2] / 'data' / 'analyze_drop_golden.json').read_text())


def test_an_error_result_still_has_every_key_in_the_contract_order():
    result = Identification(Status.ERROR, 'none')
    data = result.as_dict()
    # The modes came after the golden keys: an empty list when there is no estimate.
    assert set(data) == {*GOLDEN['analyze_json'], 'modes'} and data['modes'] == []
    # The flat order (as the fields were declared before they were grouped).
    assert list(data)[:3] == ['status', 'message', 'method']
    assert [k for k in data if k not in ('status', 'message', 'modes')] == [
        k for k, _ in GOLDEN['beam_params']
    ]
    assert {*CONTRACT_KEYS, *(f'{k}_std' for k in CONTRACT_KEYS)} <= set(data)
    assert result.key_values()[-1] == ('mode_count', '0')


def test_modes_are_a_list_in_json_and_numbered_keys_on_beam_params():
    modes = (
        IdentifiedMode(Estimate(3.06, 1e-5), Estimate(0.0024, 4e-7), 0.04),
        IdentifiedMode(Estimate(38.7, 2e-3), Estimate(0.03, 1e-3), 1e-4),
    )
    result = Identification(Status.OK, 'ok', modes=modes)
    assert result.as_dict()['modes'][1] == {
        'natural_frequency_hz': 38.7,
        'natural_frequency_hz_std': 2e-3,
        'damping_ratio': 0.03,
        'damping_ratio_std': 1e-3,
        'amplitude_m': 1e-4,
    }
    pairs = result.key_values()
    assert pairs[-5:] == [
        ('mode_count', '2'),
        ('mode_2_natural_frequency_hz', '38.7'),
        ('mode_2_natural_frequency_hz_std', '0.002'),
        ('mode_2_damping_ratio', '0.03'),
        ('mode_2_damping_ratio_std', '0.001'),
    ]
    # The shaper reads exactly these keys back.
    level = int(Status.OK)
    estimate = estimate_from_status(level, {**dict(pairs), **_first(modes[0])}, max_modes=3)
    assert [m.mode.frequency_hz for m in estimate.modes] == [3.06, 38.7]
    assert estimate.modes[1].damping_std == 1e-3


def _first(mode):
    return {
        'natural_frequency_hz': repr(mode.natural_frequency_hz.value),
        'natural_frequency_hz_std': repr(mode.natural_frequency_hz.std),
        'damping_ratio': repr(mode.damping_ratio.value),
        'damping_ratio_std': repr(mode.damping_ratio.std),
    }


def test_an_estimate_gives_its_key_and_its_std():
    result = Identification(
        Status.OK,
        'ok',
        estimates=Estimates(damping_ratio=Estimate(0.002, 1e-6)),
        release=ReleaseFigures(time_s=Estimate(2.0, 0.001), source='tip_load'),
        samples=SampleCounts(received=12, non_finite=2),
    )
    data = result.as_dict()
    assert (data['damping_ratio'], data['damping_ratio_std']) == (0.002, 1e-6)
    assert (data['release_time_s'], data['release_time_s_std']) == (2.0, 0.001)
    assert data['release_source'] == 'tip_load' and data['status'] == 'OK'
    assert (data['n_samples'], data['n_rejected']) == (10, 2)
    pairs = dict(result.key_values())
    assert pairs['damping_ratio_std'] == '1e-06' and pairs['n_rejected'] == '2.0'
    assert 'status' not in pairs and 'message' not in pairs


@pytest.mark.parametrize(
    ('key', 'value', 'std'),
    [('damping_ratio', 0.002, 1e-6), ('release_confidence', 0.0, math.nan)],
)
def test_figure_by_its_contract_key(key, value, std):
    result = Identification(
        Status.OK, 'ok', estimates=Estimates(damping_ratio=Estimate(0.002, 1e-6))
    )
    figure = result.figure(key)
    assert figure.value == value
    assert figure.std == std or (math.isnan(figure.std) and math.isnan(std))


@pytest.mark.parametrize('key', ['release_source', 'method', 'no_such_key'])
def test_figure_of_a_text_or_unknown_key_is_a_key_error(key):
    with pytest.raises(KeyError):
        Identification(Status.OK, 'ok').figure(key)


def test_results_are_frozen():
    with pytest.raises(dataclasses.FrozenInstanceError):
        Estimate().value = 1.0  # type: ignore[misc]
    assert math.isnan(Estimate().value) and math.isnan(Estimate().std)
