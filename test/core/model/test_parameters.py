from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.base.errors import ConfigError
from lumpbeam_ros.core.model.parameters import (
    EFFECT_PARAMETERS,
    EFFECTS,
    BeamParameters,
    DropTestConfig,
    Effects,
    effect_value_problem,
    load_beam_config,
    write_beam_config,
)
from lumpbeam_ros.core.model.simulate import simulate_drop_test

GOOD = """\
/**:
  ros__parameters:
    beam:
      length_m: 2.0
      n_segments: 4
    tip:
      mass_kg: 1.0
"""


def test_default_config_is_spec_section_1():
    beam, drop = load_beam_config()
    assert beam == BeamParameters()
    assert drop == DropTestConfig()


def test_partial_file_takes_defaults(tmp_path):
    path = tmp_path / 'beam.yaml'
    path.write_text(GOOD)
    beam, _ = load_beam_config(path)
    assert (beam.length_m, beam.n_segments, beam.tip_mass_kg) == (2.0, 4, 1.0)
    assert beam.k_total_nm_per_rad == BeamParameters().k_total_nm_per_rad


def test_roundtrip(tmp_path):
    beam = BeamParameters(n_segments=7, tip_placement='segment_com')
    effects = beam.effects.with_effect('added_mass', 0.3).with_effect('sensor_scale', 1.04)
    effects = effects.with_effect('cubic_stiffness', -2e7).with_effect('mount_tilt', -0.03)
    beam = replace(beam, effects=effects)
    path = tmp_path / 'out.yaml'
    write_beam_config(path, beam, DropTestConfig(load_kg=3.0), header='written by a test')
    assert load_beam_config(path) == (beam, DropTestConfig(load_kg=3.0))
    assert path.read_text().startswith('# written by a test')


@pytest.mark.parametrize(
    ('body', 'key', 'problem'),
    [
        ('beam:\n      length_m: -1.0', 'beam.length_m', 'must be positive'),
        ('beam:\n      mass_kg: 0', 'beam.mass_kg', 'must be positive'),
        ('beam:\n      k_total_nm_per_rad: 0.0', 'beam.k_total_nm_per_rad', 'must be positive'),
        ('beam:\n      n_segments: 0', 'beam.n_segments', 'at least 1'),
        ('beam:\n      n_segments: 2.5', 'beam.n_segments', 'integer'),
        ('beam:\n      length_m: abc', 'beam.length_m', 'number'),
        ('beam:\n      length_m: .nan', 'beam.length_m', 'finite'),
        ('beam:\n      lenght_m: 2.0', 'beam.lenght_m', 'unknown key'),
        ('tip:\n      placement: middle', 'tip.placement', 'must be one of'),
        ('tip:\n      mass_kg: -2.5', 'tip.mass_kg', 'must be non-negative'),
        (
            'effects:\n      sensor_scale:\n        scale: 0.0',
            'effects.sensor_scale.scale',
            'must be in (0, 10]',
        ),
        (
            'effects:\n      mount_tilt:\n        tilt_rad: -2.0',
            'effects.mount_tilt.tilt_rad',
            'must be in [-1.5, 1.5]',
        ),
        (
            'effects:\n      added_mass:\n        mass_kg: -0.1',
            'effects.added_mass.mass_kg',
            'must be in [0, 100]',
        ),
    ],
)
def test_bad_values_name_file_and_key(tmp_path, body, key, problem):
    path = tmp_path / 'bad.yaml'
    path.write_text(f'/**:\n  ros__parameters:\n    {body}\n')
    with pytest.raises(ConfigError) as caught:
        load_beam_config(path)
    assert caught.value.key == key
    assert str(path) in str(caught.value)
    assert problem in str(caught.value)


@pytest.mark.parametrize(
    'text',
    ['beam: [1, 2', 'just a string', '/**:\n  parameters: {}\n', '/**:\n  ros__parameters: 3\n'],
)
def test_malformed_files(tmp_path, text):
    path = tmp_path / 'bad.yaml'
    path.write_text(text)
    with pytest.raises(ConfigError):
        load_beam_config(path)


def test_missing_file():
    with pytest.raises(ConfigError, match='no such file'):
        load_beam_config('/nonexistent/beam.yaml')


def test_cli_reports_one_line_and_exit_2(tmp_path, capsys):
    path = tmp_path / 'bad.yaml'
    path.write_text('/**:\n  ros__parameters:\n    beam:\n      length_m: -2.3\n')
    assert main(['reproduce', '--config', str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count('\n') == 0
    assert 'beam.length_m' in err and str(path) in err
    assert 'Traceback' not in err


def _ends(record):
    """The ends of an effect's limits, an open end taken just inside."""
    limits, ends = record.limits, []
    if limits.low is not None:
        ends.append(
            limits.low + (1e-6 * max(abs(limits.high or 1.0), 1.0) if limits.low_open else 0.0)
        )
    if limits.high is not None:
        ends.append(limits.high)
    return ends


_BOUND_CASES = [(r.name, v) for r in Effects.records() for v in _ends(r)]


@pytest.mark.filterwarnings('error')
@pytest.mark.parametrize(
    ('name', 'value'), _BOUND_CASES, ids=[f'{n}={v:g}' for n, v in _BOUND_CASES]
)
def test_the_model_simulates_each_effect_at_each_end_of_its_limits(name, value):
    # A value the limits take reaches the simulator node and the diagnosis's prediction: the
    # drop test (loaded, released, ringing) must run to its end with a finite pose there.
    beam, _ = load_beam_config()
    beam = replace(beam, effects=beam.effects.with_effect(name, value))
    assert effect_value_problem(name, value) is None
    trajectory = simulate_drop_test(beam, DropTestConfig(4.5, 0.1, 1.0), rate_hz=100.0)
    assert trajectory.t.size == 101
    assert np.all(np.isfinite(trajectory.z)) and np.all(np.isfinite(trajectory.pitch))


@pytest.mark.parametrize(
    ('name', 'value'),
    [
        ('cubic_stiffness', -1e12),
        ('cubic_stiffness', 1e12),
        ('added_mass', 1e4),
        ('mount_tilt', 1.6),
    ],
)
def test_values_the_model_cannot_simulate_are_refused(name, value):
    assert effect_value_problem(name, value) is not None


def test_every_effect_is_one_record():
    records = Effects.records()
    assert [r.name for r in records] == list(EFFECTS) == list(EFFECT_PARAMETERS)
    for record in records:
        effects = Effects().with_effect(record.name, record.off)
        assert effects == Effects() and effects.active() == {}
        assert record.limits.contains(record.off)
        assert record.hook in ('chain', 'stamps', 'position')


def test_the_interface_documents_each_effects_limits():
    text = (Path(__file__).resolve().parents[3] / 'doc' / 'interfaces.md').read_text()
    section = text.partition('## Missing effects')[2].partition('\n## ')[0]
    rows = {
        line.split(' | ')[0].strip('|` '): line.split(' | ')[-2]
        for line in section.splitlines()
        if line.startswith('| `')
    }
    assert rows == {name: r.limits.notation() for name, r in EFFECTS.items()}
