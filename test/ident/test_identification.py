import dataclasses
import json
import math
from pathlib import Path

import pytest

from lumpbeam_ros.bagio.tipseries import SampleCounts
from lumpbeam_ros.cli.analyze import CONTRACT_KEYS
from lumpbeam_ros.ident.identification import (
    Estimate,
    Estimates,
    Identification,
    ReleaseFigures,
    Status,
)

GOLDEN = json.loads((Path(__file__).parents[1] / 'data' / 'analyze_drop_golden.json').read_text())


def test_an_error_result_still_has_every_key_in_the_contract_order():
    data = Identification(Status.ERROR, 'none').as_dict()
    assert set(data) == set(GOLDEN['analyze_json'])
    # The flat order (as the fields were declared before they were grouped).
    assert list(data)[:3] == ['status', 'message', 'method']
    assert [k for k in data if k not in ('status', 'message')] == [
        k for k, _ in GOLDEN['beam_params']
    ]
    assert {*CONTRACT_KEYS, *(f'{k}_std' for k in CONTRACT_KEYS)} <= set(data)


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
