import math

import pytest

from lumpbeam_ros.base.interface import SIMULATOR_NODE
from lumpbeam_ros.core.model.parameters import (
    EFFECT_OFF,
    EFFECT_PARAMETERS,
    EFFECTS,
    Effects,
    effect_value_problem,
)
from lumpbeam_ros.nodes.params.simulator_params import SIMULATOR_SCHEMA, effect_parameter_name


def test_every_effect_is_a_run_time_parameter_with_the_models_default():
    assert SIMULATOR_SCHEMA.node == SIMULATOR_NODE
    for effect, parameter in EFFECT_PARAMETERS.items():
        name = effect_parameter_name(effect)
        assert name == f'effects.{effect}.{parameter}' and name in SIMULATOR_SCHEMA
        spec = SIMULATOR_SCHEMA[name]
        assert spec.kind == 'double' and not spec.read_only
        assert spec.default == Effects().value(effect) == EFFECT_OFF[effect]  # off by default
        assert spec.unit == EFFECTS[effect].unit and spec.bounds == EFFECTS[effect].limits
    # Every parameter but the arm's can be changed while the node runs (the summary says so).
    read_only = {spec.name for spec in SIMULATOR_SCHEMA if spec.read_only}
    assert read_only == {'arm_config', 'arm_commands', 'arm_ring_down_s', 'arm_history_s'}


def test_an_unknown_effect_has_no_parameter():
    with pytest.raises(KeyError):
        effect_parameter_name('gremlins')


def _probes(effect):
    """Values at and around the ends of the node's bounds and of the model's limits."""
    bounds = SIMULATOR_SCHEMA[effect_parameter_name(effect)].bounds
    limits = EFFECTS[effect].limits
    ends = [v for v in (bounds.low, bounds.high, limits.low, limits.high) if v is not None]
    return sorted({e + d for e in ends for d in (-1e-9, 0.0, 1e-9)} | {-1e12, 1e12, math.nan})


@pytest.mark.parametrize('effect', sorted(EFFECT_PARAMETERS))
def test_the_node_never_accepts_what_the_model_refuses(effect):
    # A value the node takes goes straight into the model's Effects: it must be physical.
    name = effect_parameter_name(effect)
    for value in _probes(effect):
        if SIMULATOR_SCHEMA.problem(name, value) is None:
            assert effect_value_problem(effect, value) is None, value


@pytest.mark.parametrize(
    ('effect', 'value', 'problem'),
    [
        ('sensor_latency', -0.001, 'in [0, 1]'),
        ('sensor_latency', 1.5, 'in [0, 1]'),
        ('sensor_scale', 0.0, 'in (0, 10]'),
        ('mount_tilt', math.pi / 2, 'in [-1.5, 1.5]'),
        ('base_compliance', -1.0, 'in [0, 1e+10]'),
        ('cubic_stiffness', math.inf, 'finite'),
        ('cubic_stiffness', -1e12, 'in [-1e+08, 1e+09]'),
    ],
)
def test_bad_effect_values_are_named(effect, value, problem):
    name = effect_parameter_name(effect)
    assert problem in SIMULATOR_SCHEMA.problem(name, value)


@pytest.mark.parametrize(
    ('name', 'value', 'problem'),
    [
        ('rate_hz', 0.5, 'in [1, 2000]'),
        ('markers_rate_hz', -1.0, 'in [0, 200]'),
        ('max_catch_up_s', 0.0, 'in [0.01, 3600]'),
        ('adopt_identified', 'true', 'true or false'),
        ('beam_config', None, 'must be a string'),
    ],
)
def test_bad_values_are_named(name, value, problem):
    assert problem in SIMULATOR_SCHEMA.problem(name, value)


def test_zero_markers_rate_is_no_markers():
    assert SIMULATOR_SCHEMA.problem('markers_rate_hz', 0.0) is None
