"""User errors: one line naming the input; the command line exits 2 without a traceback."""

from pathlib import Path

import pytest

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.base.errors import BagError, ConfigError, LumpbeamError


@pytest.mark.parametrize(
    ('source', 'key', 'problem', 'message'),
    [
        ('beam.yaml', 'beam.length_m', 'must be positive, got -1.0',
         'beam.yaml: beam.length_m: must be positive, got -1.0'),
        (Path('/c/camera.yaml'), '', 'no such file', '/c/camera.yaml: no such file'),
    ],
)  # fmt: skip
def test_config_error_names_file_key_and_problem(source, key, problem, message):
    error = ConfigError(source, key, problem)
    assert str(error) == message
    assert (error.source, error.key, error.problem) == (str(source), key, problem)
    assert isinstance(error, LumpbeamError)


def test_bag_errors_are_user_errors():
    assert issubclass(BagError, LumpbeamError)


@pytest.mark.parametrize(
    'args',
    [
        ['analyze', '/no/such/bag'],
        ['diagnose', '/no/such/bag'],
    ],
)
def test_the_command_line_prints_one_line_and_exits_2(args, capsys):
    assert main(args) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1
    assert '/no/such/bag' in err and 'Traceback' not in err
