"""Parameter files read without ROS, against ROS's own reader, and every malformed input."""

import math

import pytest

from lumpbeam_ros.base.errors import ConfigError
from lumpbeam_ros.base.paramfile import (
    check_known_keys,
    flatten,
    get_choice,
    get_float,
    get_int,
    read_parameter_file,
)
from lumpbeam_ros.base.resources import config_path

CONFIGS = [
    'paper_beam.yaml',
    'camera.yaml',
    'identifier.yaml',
    'simulator.yaml',
    'diagnosis.yaml',
    'shaper.yaml',
]


@pytest.mark.parametrize('name', CONFIGS)
def test_package_configs_read_as_a_node_reads_them(name):
    # A node given --params-file reads the file with rcl's own YAML parser (not rclpy's
    # parameter_dict_from_yaml_file, which turns 5.0e-6 into the string '5e-06').
    rclpy = pytest.importorskip('rclpy')
    path = config_path(name)
    context = rclpy.Context()
    rclpy.init(args=['--ros-args', '--params-file', str(path)], context=context)
    try:
        node = rclpy.create_node(
            'paramfile_test', context=context, automatically_declare_parameters_from_overrides=True
        )
        # The parameters every node declares itself (use_sim_time, ...): not from the file.
        bare = rclpy.create_node('bare', context=context, use_global_arguments=False)
        own = set(bare._parameters)
        ros = {p.name: p.value for p in node.get_parameters(set(node._parameters) - own)}
        node.destroy_node()
        bare.destroy_node()
    finally:
        rclpy.shutdown(context=context)
    assert read_parameter_file(path) == ros


def test_flatten_names_nested_keys_with_dots():
    tree = {'beam': {'length_m': 2.31, 'tip': {'mass_kg': 0.4}}, 'rate_hz': 180}
    assert flatten(tree) == {'beam.length_m': 2.31, 'beam.tip.mass_kg': 0.4, 'rate_hz': 180}
    assert flatten({}) == {}


def test_sections_merge_in_file_order(tmp_path):
    path = tmp_path / 'p.yaml'
    path.write_text(
        '/**:\n  ros__parameters:\n    a: 1\n    b: {c: 2}\nnode:\n  ros__parameters:\n    a: 3\n'
    )
    assert read_parameter_file(path) == {'a': 3, 'b.c': 2}


@pytest.mark.parametrize(
    ('text', 'problem'),
    [
        ('a: [1, 2\n', 'not valid YAML at line'),
        ('', 'expected a mapping of node names'),
        ('- 1\n- 2\n', 'expected a mapping of node names'),
        ('node: 3\n', 'node: expected a ros__parameters mapping'),
        ('node:\n  parameters: {a: 1}\n', 'node: expected a ros__parameters mapping'),
        ('node:\n  ros__parameters: 5\n', 'node: expected a ros__parameters mapping'),
    ],
)
def test_malformed_files_are_named_with_the_problem(tmp_path, text, problem):
    path = tmp_path / 'bad.yaml'
    path.write_text(text)
    with pytest.raises(ConfigError) as caught:
        read_parameter_file(path)
    assert str(caught.value).startswith(f'{path}: ')
    assert problem in str(caught.value)


def test_missing_and_unreadable_files(tmp_path):
    with pytest.raises(ConfigError, match='no such file'):
        read_parameter_file(tmp_path / 'absent.yaml')
    with pytest.raises(ConfigError, match='cannot read'):
        read_parameter_file(tmp_path)  # a folder
    binary = tmp_path / 'binary.yaml'
    binary.write_bytes(b'\xff\xfe\x00')
    with pytest.raises(ConfigError, match='cannot read'):
        read_parameter_file(binary)


def test_unknown_keys_are_refused_first_in_sorted_order():
    check_known_keys({'a': 1, 'b': 2}, {'a', 'b', 'c'}, 'f.yaml')
    with pytest.raises(ConfigError, match=r'^f\.yaml: beam\.lenght_m: unknown key$'):
        check_known_keys({'z': 1, 'beam.lenght_m': 2}, {'a'}, 'f.yaml')


@pytest.mark.parametrize(
    ('value', 'options', 'problem'),
    [
        ('2.0', {}, 'must be a number'),
        (True, {}, 'must be a number'),
        (None, {}, 'must be a number'),
        (math.nan, {}, 'must be finite'),
        (math.inf, {}, 'must be finite'),
        (0.0, {'positive': True}, 'must be positive'),
        (-1e-9, {'non_negative': True}, 'must not be negative'),
    ],
)
def test_get_float_refuses(value, options, problem):
    with pytest.raises(ConfigError, match=f'^f.yaml: x: {problem}'):
        get_float({'x': value}, 'x', 'f.yaml', **options)


def test_get_float_accepts_integers_and_defaults():
    assert get_float({'x': 3}, 'x', 'f') == 3.0 and isinstance(
        get_float({'x': 3}, 'x', 'f'), float
    )
    assert get_float({}, 'x', 'f', 0.5) == 0.5
    assert get_float({'x': 0.0}, 'x', 'f', non_negative=True) == 0.0
    with pytest.raises(ConfigError, match='x: missing'):
        get_float({}, 'x', 'f')


@pytest.mark.parametrize(
    ('value', 'problem'),
    [(2.0, 'must be an integer'), (False, 'must be an integer'), ('3', 'must be an integer'),
     (0, 'must be at least 1')],
)  # fmt: skip
def test_get_int_refuses(value, problem):
    with pytest.raises(ConfigError, match=problem):
        get_int({'n': value}, 'n', 'f', minimum=1)


def test_get_int_and_get_choice_accept_and_default():
    assert get_int({'n': 4}, 'n', 'f', minimum=4) == 4
    assert get_int({}, 'n', 'f', 7) == 7
    with pytest.raises(ConfigError, match='n: missing'):
        get_int({}, 'n', 'f')
    choices = ('plane', 'free')
    assert get_choice({'m': 'free'}, 'm', 'f', choices) == 'free'
    assert get_choice({}, 'm', 'f', choices, 'plane') == 'plane'
    for bad in ('Free', 3, None):
        with pytest.raises(ConfigError, match='m: '):
            get_choice({'m': bad}, 'm', 'f', choices)
    with pytest.raises(ConfigError, match='m: missing'):
        get_choice({}, 'm', 'f', choices)


def test_safe_load_parses_as_yaml_safe_load_and_refuses_python_objects():
    import yaml

    from lumpbeam_ros.base.paramfile import safe_load

    text = 'a: [1, 2.5, -3e-4]\nb: {c: true, d: null, e: "x"}\n'
    assert safe_load(text) == yaml.safe_load(text)
    with pytest.raises(yaml.YAMLError):
        safe_load('!!python/object/apply:os.system ["true"]')


def test_the_one_loader_reads_the_given_file_or_the_packages_own(tmp_path):
    from lumpbeam_ros.base.paramfile import parameter_file
    from lumpbeam_ros.base.resources import config_path

    source, params = parameter_file(None, 'identifier.yaml')
    assert source == config_path('identifier.yaml') and 'window.length_s' in params
    given = tmp_path / 'mine.yaml'
    given.write_text('/**:\n  ros__parameters:\n    window:\n      length_s: 3.0\n')
    assert parameter_file(given, 'identifier.yaml') == (given, {'window.length_s': 3.0})
    with pytest.raises(ConfigError, match='no_such.yaml'):
        parameter_file(tmp_path / 'no_such.yaml', 'identifier.yaml')
