import dataclasses
import typing

import pytest

from lumpbeam_ros.base.interface import DIAGNOSIS_NODE, SIMULATOR_NODE
from lumpbeam_ros.core.diagnose.live import LiveDiagnosisConfig, Trigger
from lumpbeam_ros.nodes.params.diagnosis_params import DIAGNOSIS_SCHEMA

#: The node's parameter of each LiveDiagnosisConfig field (nodes/diagnosis_node.py builds it so).
LIVE_PARAMETERS = {
    'trigger': 'trigger',
    'pre_release_s': 'ring_down.pre_release_s',
    'decay_s': 'ring_down.decay_s',
    'min_amplitude_m': 'ring_down.min_amplitude_m',
    'window_s': 'window_s',
    'keep_s': 'keep_s',
    'reset_jump_back_s': 'stream.reset_jump_back_s',
}


def test_the_live_settings_defaults_are_the_schemas():
    # Every parameter is a field; max_rate_hz sizes the buffers and is not a parameter.
    fields = {f.name for f in dataclasses.fields(LiveDiagnosisConfig)}
    assert fields - set(LIVE_PARAMETERS) == {'max_rate_hz'}
    defaults = DIAGNOSIS_SCHEMA.defaults()
    assert (
        LiveDiagnosisConfig(**{f: defaults[p] for f, p in LIVE_PARAMETERS.items()})
        == LiveDiagnosisConfig()
    )


def test_the_triggers_are_the_live_buffers():
    assert DIAGNOSIS_SCHEMA['trigger'].choices == typing.get_args(Trigger)


def test_the_default_buffer_holds_a_whole_ring_down_and_a_whole_window():
    d = DIAGNOSIS_SCHEMA.defaults()
    assert d['keep_s'] > d['ring_down.pre_release_s'] + d['ring_down.decay_s']
    assert d['keep_s'] > d['window_s']
    # ... and the smallest keep_s allowed holds the shortest ring-down and window allowed.
    keep = DIAGNOSIS_SCHEMA['keep_s'].bounds.low
    assert keep >= DIAGNOSIS_SCHEMA['ring_down.decay_s'].bounds.low
    assert keep >= DIAGNOSIS_SCHEMA['window_s'].bounds.low


def test_the_node_names_and_what_may_change_while_it_runs():
    assert DIAGNOSIS_SCHEMA.node == DIAGNOSIS_NODE
    assert DIAGNOSIS_SCHEMA[SIMULATOR_NODE].default == SIMULATOR_NODE
    assert [spec.name for spec in DIAGNOSIS_SCHEMA if not spec.read_only] == ['adopt']


@pytest.mark.parametrize(
    ('name', 'value', 'problem'),
    [
        ('trigger', 'always', 'one of ring_down, window'),
        ('worker', 'gpu', 'one of process, thread'),
        ('ring_down.decay_s', 1.0, 'in [2, 600]'),  # 2 s of decay: the least a fit needs
        ('ring_down.pre_release_s', 0.0, 'positive'),
        ('window_s', 1000.0, 'in [2, 600]'),
        ('keep_s', 1.0, 'in [5, 3600]'),
        ('status_period_s', 0.0, 'in [0.05, 60]'),
        ('adopt', 'no', 'true or false'),
    ],
)
def test_bad_values_are_named(name, value, problem):
    assert problem in DIAGNOSIS_SCHEMA.problem(name, value)


def test_good_values_pass():
    values = {'trigger': 'window', 'window_s': 20.0, 'keep_s': 90, 'worker': 'thread'}
    assert DIAGNOSIS_SCHEMA.first_problem(values) is None
