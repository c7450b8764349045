import dataclasses

import pytest

from lumpbeam_ros.base.errors import ConfigError
from lumpbeam_ros.base.interface import IDENTIFIER_NODE
from lumpbeam_ros.core.ident.settings import (
    IDENTIFIER_SETTINGS,
    NONLINEAR_CHOICES,
    IdentifierConfig,
    config_from_parameters,
)
from lumpbeam_ros.nodes.params.identifier_params import IDENTIFIER_SCHEMA, NODE_ONLY


def test_identifier_schema_is_the_identifier_config():
    settings = {spec.name for spec in IDENTIFIER_SETTINGS}
    assert settings <= set(IDENTIFIER_SCHEMA.names)
    assert set(IDENTIFIER_SCHEMA.names) - settings == set(NODE_ONLY)
    defaults = IDENTIFIER_SCHEMA.defaults()
    assert config_from_parameters({k: defaults[k] for k in settings}, 'schema') == (
        IdentifierConfig()
    )


def test_every_setting_of_the_identifier_is_a_parameter():
    fields = dataclasses.fields(IdentifierConfig)
    assert [f.metadata['parameter'] for f in fields] == list(IDENTIFIER_SETTINGS)
    assert [getattr(IdentifierConfig(), f.name) for f in fields] == [
        spec.default for spec in IDENTIFIER_SETTINGS
    ]
    assert IDENTIFIER_SCHEMA.node == IDENTIFIER_NODE
    assert all(spec.read_only for spec in IDENTIFIER_SCHEMA)  # the summary says so
    assert IDENTIFIER_SCHEMA['fit.nonlinear'].choices == NONLINEAR_CHOICES


def test_the_effective_mass_fraction_is_rayleighs():
    # The first mode of a uniform cantilever moves 33/140 of the beam's mass with the tip.
    assert IDENTIFIER_SCHEMA['effective_mass.beam_fraction'].default == pytest.approx(
        33 / 140, abs=5e-5
    )


@pytest.mark.parametrize(
    ('values', 'key', 'message'),
    [
        ({'fit.min_frequency_hz': 5.0, 'fit.max_frequency_hz': 5.0}, 'max_frequency_hz', 'exceed'),
        ({'fit.min_frequency_hz': 8.0, 'fit.max_frequency_hz': 4.0}, 'max_frequency_hz', 'exceed'),
    ],
)
def test_what_one_value_cannot_show_is_refused_by_the_configuration(values, key, message):
    assert IDENTIFIER_SCHEMA.first_problem(values) is None
    with pytest.raises(ConfigError, match=f'{key}.*{message}'):
        config_from_parameters(values, 'probe')


@pytest.mark.parametrize(
    ('name', 'value', 'problem'),
    [
        ('window.length_s', 0.0, 'must be positive'),
        ('window.length_s', float('inf'), 'must be finite'),
        ('publish_rate_hz', 500.0, 'in [0.01, 100]'),
        ('fit.max_modes', 9, 'in [1, 8]'),
        ('fit.max_modes', 1.5, 'must be an integer'),
        ('fit.nonlinear', 'sometimes', 'one of auto, always, never'),
        ('effective_mass.beam_fraction', 0.0, 'in (0, 1]'),
        ('quality.min_release_confidence', 1.01, 'in (0, 1]'),
        ('fit.drift', 1, 'true or false'),
    ],
)
def test_bad_values_are_named(name, value, problem):
    assert (
        IDENTIFIER_SCHEMA.problem(name, value)
        == f'{name}: {IDENTIFIER_SCHEMA[name].problem(value)}'
    )
    assert problem in IDENTIFIER_SCHEMA.problem(name, value)
