import re

import pytest

from lumpbeam_ros.base.errors import ConfigError
from lumpbeam_ros.base.paramfile import read_parameter_file
from lumpbeam_ros.base.resources import config_path
from lumpbeam_ros.core.ident.settings import (
    IDENTIFIER_SETTINGS,
    IdentifierConfig,
    config_from_parameters,
    config_to_parameters,
    load_identifier_config,
)


def test_default_file_matches_the_dataclass_and_documents_every_key():
    path = config_path('identifier.yaml')
    assert load_identifier_config() == IdentifierConfig()
    assert set(read_parameter_file(path)) == {spec.name for spec in IDENTIFIER_SETTINGS}
    lines = path.read_text().splitlines()
    for i, line in enumerate(lines):
        match = re.match(r'\s+(\w+): \S', line)
        if match:  # a leaf key: a comment must come right before it
            assert lines[i - 1].strip().startswith('#'), f'undocumented key {match[1]}'


def test_round_trip_through_parameters():
    config = IdentifierConfig(window_s=5.0, max_modes=1, drift=True)
    assert config_from_parameters(config_to_parameters(config), 'x') == config


@pytest.mark.parametrize(
    ('key', 'value', 'problem'),
    [
        ('window.length_s', -1.0, 'must be positive'),
        ('window.length_s', 'long', 'must be a number'),
        ('fit.max_modes', 9, r'must be in \[1, 8\], got 9'),
        ('fit.max_modes', 0, r'must be in \[1, 8\], got 0'),
        ('fit.drift', 'yes', 'true or false'),
        ('fit.nonlinear', 'sometimes', 'one of'),
        ('fit.shift_prior_std', -0.1, 'must be non-negative|must be >= 0|must be in'),
        ('fit.shift_prior_std', 'a tenth', 'must be a number'),
        ('fit.nonlinear_min_decay', 0.0, 'must be positive'),
        ('fit.min_frequency_hz', 50.0, 'must exceed'),
        ('quality.min_release_confidence', 2.0, r'must be in \(0, 1\]'),
        ('window.lenght_s', 10.0, 'unknown key'),
    ],
)
def test_bad_values_name_file_and_key(tmp_path, key, value, problem):
    section, _, leaf = key.rpartition('.')
    path = tmp_path / 'identifier.yaml'
    path.write_text(f'/**:\n  ros__parameters:\n    {section}:\n      {leaf}: {value!r}\n')
    with pytest.raises(ConfigError, match=problem) as info:
        load_identifier_config(path)
    assert str(path) in str(info.value)
    assert info.value.key in (key, 'fit.max_frequency_hz')


def test_missing_file_is_a_config_error(tmp_path):
    with pytest.raises(ConfigError, match='no such file'):
        load_identifier_config(tmp_path / 'nope.yaml')
