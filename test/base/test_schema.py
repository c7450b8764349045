import doctest
import math

import pytest

from lumpbeam_ros.base import schema as schema_module
from lumpbeam_ros.base.errors import ConfigError
from lumpbeam_ros.base.paramfile import read_parameter_file
from lumpbeam_ros.base.resources import config_path
from lumpbeam_ros.base.schema import Bounds, ParameterSchema, ParameterSpec
from lumpbeam_ros.core.ident.settings import IDENTIFIER_SETTINGS, config_from_parameters
from lumpbeam_ros.core.vision.config import camera_config_from_parameters
from lumpbeam_ros.nodes.params.camera_params import CAMERA_SCHEMA, CONFIG_KEYS
from lumpbeam_ros.nodes.params.identifier_params import IDENTIFIER_SCHEMA
from lumpbeam_ros.nodes.params.reference import SCHEMAS


def test_module_examples_run():
    assert doctest.testmod(schema_module).failed == 0


@pytest.mark.parametrize(
    ('bounds', 'inside', 'outside', 'words', 'notation'),
    [
        (Bounds(0.0, low_open=True), [1e-12, 1e9], [0.0, -1.0, math.nan], 'positive', '> 0'),
        (Bounds(0.0), [0.0, 3.0], [-1e-12, math.nan], 'non-negative', '>= 0'),
        (Bounds(64), [64, 65], [63], 'at least 64', '>= 64'),
        (Bounds(0.0, 1.0, low_open=True), [1.0, 0.5], [0.0, 1.0 + 1e-12], 'in (0, 1]', '(0, 1]'),
        (Bounds(0.0, 0.5, True, True), [0.25], [0.0, 0.5], 'in (0, 0.5)', '(0, 0.5)'),
        (Bounds(high=2.0), [-5.0, 2.0], [2.5], 'at most 2', '<= 2'),
    ],
)
def test_bounds(bounds, inside, outside, words, notation):
    assert all(bounds.contains(v) for v in inside)
    assert not any(bounds.contains(v) for v in outside)
    assert bounds.describe() == words and bounds.notation() == notation


@pytest.mark.parametrize(
    ('spec', 'value', 'problem'),
    [
        (ParameterSpec('b', 'bool', False, ''), 1, 'must be true or false, got 1'),
        (ParameterSpec('i', 'int', 2, '', bounds=Bounds(1, 2)), 2.0, 'must be an integer'),
        (ParameterSpec('i', 'int', 2, '', bounds=Bounds(1, 2)), 3, 'must be in [1, 2], got 3'),
        (ParameterSpec('i', 'int', 2, ''), True, 'must be an integer, got True'),
        (ParameterSpec('d', 'double', 1.0, ''), 'fast', "must be a number, got 'fast'"),
        (ParameterSpec('d', 'double', 1.0, ''), math.inf, 'must be finite'),
        (ParameterSpec('d', 'double', 1.0, '', bounds=Bounds(0, low_open=True)), 0, 'positive'),
        (ParameterSpec('s', 'string', 'a', '', choices=('a', 'b')), 'c', 'one of a, b'),
        (ParameterSpec('s', 'string', 'a', ''), 3, 'must be a string'),
        (ParameterSpec('v', 'double[]', (0.0, 0.0), '', length=2), [1.0], 'a list of 2 finite'),
        (ParameterSpec('v', 'double[]', (0.0, 0.0), '', length=2), [1.0, 'x'], 'a list of 2'),
        (ParameterSpec('v', 'double[]', (0.0, 0.0), '', length=2), 'ab', 'a list of 2'),
        (
            ParameterSpec('v', 'double[]', (1.0,), '', bounds=Bounds(0.0), length=1),
            [-1.0],
            'every element must be non-negative',
        ),
    ],
)
def test_spec_refuses_with_a_reason(spec, value, problem):
    assert problem in spec.problem(value)


@pytest.mark.parametrize(
    ('spec', 'value'),
    [
        (ParameterSpec('d', 'double', 1.0, '', bounds=Bounds(0.0, 2.0)), 2),  # YAML's 2 for 2.0
        (ParameterSpec('v', 'double[]', (0.0, 0.0), '', length=2), (1, 2.5)),
        (ParameterSpec('s', 'string', 'a', '', choices=('a', 'b')), 'b'),
        (ParameterSpec('i', 'int', 5, '', bounds=Bounds(1)), 10**12),
    ],
)
def test_spec_accepts(spec, value):
    assert spec.problem(value) is None


@pytest.mark.parametrize(
    ('kwargs', 'message'),
    [
        ({'kind': 'double', 'default': -1.0, 'bounds': Bounds(0.0)}, 'default -1.0'),
        ({'kind': 'string', 'default': 'a', 'bounds': Bounds(0.0)}, 'bounds on a string'),
        ({'kind': 'double', 'default': 1.0, 'choices': ('a',)}, 'choices on a double'),
        ({'kind': 'double[]', 'default': (1.0,)}, 'has a length'),
        ({'kind': 'double', 'default': 1.0, 'length': 1}, 'has a length'),
    ],
)
def test_an_inconsistent_spec_is_refused(kwargs, message):
    with pytest.raises(ValueError, match=message):
        ParameterSpec('x', description='', **kwargs)


def test_empty_bounds_are_refused():
    with pytest.raises(ValueError):
        Bounds()
    with pytest.raises(ValueError):
        Bounds(1.0, 1.0)


def test_schema_lookup_and_problems():
    a = ParameterSpec('a', 'double', 1.0, '', bounds=Bounds(0.0))
    b = ParameterSpec('b', 'int', 1, '')
    schema = ParameterSchema('probe', 'A probe.', (a, b))
    assert schema.names == ['a', 'b'] and schema['b'] is b and 'a' in schema
    assert schema.defaults() == {'a': 1.0, 'b': 1}
    assert schema.problem('a', -2.0) == 'a: must be non-negative, got -2.0'
    assert schema.problem('zz', 1) == 'zz: not a parameter of probe'
    assert schema.first_problem({'b': 'x', 'a': -1.0}).startswith('a: ')
    assert schema.first_problem({'a': 0.0, 'b': 4}) is None
    with pytest.raises(ValueError, match='declared twice'):
        ParameterSchema('probe', '', (a, a))


@pytest.mark.parametrize('schema', SCHEMAS, ids=lambda s: s.node)
def test_the_config_file_holds_the_schema_defaults(schema):
    values = read_parameter_file(config_path(schema.config_file))
    specs = {spec.name: spec for spec in (*schema, *schema.file_only)}
    assert set(values) <= set(specs)
    assert {name: specs[name].default for name in values} == {
        # The file's lists are the schema's tuples.
        name: tuple(v) if isinstance(v, list) else v
        for name, v in values.items()
    }
    assert schema.first_problem({k: v for k, v in values.items() if k in schema}) is None
    assert all(specs[k].problem(v) is None for k, v in values.items())


def _beyond(spec):
    """Values just outside each end of a spec's bounds."""
    bounds, step = spec.bounds, 1 if spec.kind == 'int' else 1e-6
    out = []
    if bounds.low is not None:
        out.append(bounds.low if bounds.low_open else bounds.low - step)
    if bounds.high is not None:
        out.append(bounds.high if bounds.high_open else bounds.high + step)
    return [int(v) if spec.kind == 'int' else float(v) for v in out]


# The node's timer bounds its rate; the command line reads the file without a timer.
_NODE_ONLY_BOUNDS = {'publish_rate_hz'}
_CORE_CASES = [
    (loader, spec, value)
    for loader, schema, keys in [
        (lambda p: camera_config_from_parameters(p, 'probe'), CAMERA_SCHEMA, CONFIG_KEYS),
        (
            lambda p: config_from_parameters(p, 'probe'),
            IDENTIFIER_SCHEMA,
            [s.name for s in IDENTIFIER_SETTINGS],
        ),
    ]
    for spec in schema
    if spec.name in keys and spec.bounds is not None and spec.name not in _NODE_ONLY_BOUNDS
    for value in _beyond(spec)
]


@pytest.mark.parametrize(
    ('loader', 'spec', 'value'), _CORE_CASES, ids=[f'{s.name}={v}' for _, s, v in _CORE_CASES]
)
def test_the_core_loader_refuses_what_the_schema_refuses(loader, spec, value):
    # The configuration loaders of the command line were written on their own; a bound the
    # schema states must be one they enforce too, so the node and the CLI agree.
    assert spec.problem(value) is not None
    with pytest.raises(ConfigError, match=spec.name.replace('.', r'\.')):
        loader({spec.name: value})
