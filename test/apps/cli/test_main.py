"""The lazy dispatch of ``lumpbeam``: light help, offline commands without the optional packages.

Each check runs ``lumpbeam`` in a fresh interpreter (this one has long imported everything);
a meta-path finder installed before the CLI refuses the optional packages, as on a machine
where they are not installed.
"""

import keyword
import subprocess
import sys

import pytest

from lumpbeam_ros.apps.cli.main import COMMANDS, build_parser, load_target
from lumpbeam_ros.core.model.parameters import BeamParameters, DropTestConfig
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, write_drop_test_bag

OPTIONAL = ('cv2', 'rclpy', 'matplotlib')
#: What `--help` must not load: the optional packages and the heavy core dependencies.
HEAVY = (*OPTIONAL, 'numpy', 'scipy', 'rosbags', 'mcap', 'yaml')
OFFLINE = ('reproduce', 'analyze', 'diagnose', 'compare')

BLOCKER = """
import importlib.abc
import sys

class Refuse(importlib.abc.MetaPathFinder):
    def find_spec(self, name, path=None, target=None):
        if name.partition('.')[0] in {blocked!r}:
            raise ModuleNotFoundError(f'No module named {{name!r}} (blocked)', name=name)
        return None

sys.meta_path.insert(0, Refuse())
"""
RUN_CLI = """
import atexit
atexit.register(lambda: print('loaded:', sorted(m for m in {heavy!r} if m in sys.modules)))
from lumpbeam_ros.apps.cli.main import main
sys.exit(main())
"""


def lumpbeam(*arguments: str, blocked: tuple[str, ...] = OPTIONAL) -> subprocess.CompletedProcess:
    """Runs ``lumpbeam ARGUMENTS`` in a fresh interpreter with ``blocked`` not importable."""
    code = BLOCKER.format(blocked=set(blocked)) + RUN_CLI.format(heavy=HEAVY)
    return subprocess.run(
        [sys.executable, '-c', code, *arguments], capture_output=True, text=True, timeout=300
    )


@pytest.fixture(scope='module')
def small_bag(tmp_path_factory):
    bag = tmp_path_factory.mktemp('main') / 'drop'
    write_drop_test_bag(bag, BeamParameters(), DropTestConfig(), SynthOptions(duration_s=4.0))
    return bag


@pytest.mark.parametrize('command', [[]] + [[c.name] for c in COMMANDS], ids=lambda c: str(c))
def test_help_loads_no_heavy_package(command):
    result = lumpbeam(*command, '--help')
    assert result.returncode == 0, result.stderr
    assert 'usage: lumpbeam' in result.stdout
    assert result.stdout.rstrip().endswith('loaded: []')


def test_every_command_is_listed_in_the_help():
    text = build_parser().format_help()
    assert all(command.name in text for command in COMMANDS)


def test_every_target_exists():
    for command in COMMANDS:
        # A command named by a Python keyword lives in a module with a trailing underscore.
        module = command.name + ('_' if keyword.iskeyword(command.name) else '')
        assert command.target == f'lumpbeam_ros.apps.cli.{module}:run'
        assert callable(load_target(command.target))


def test_reproduce_and_analyze_run_without_optional_packages(small_bag):
    reproduce = lumpbeam('reproduce')
    assert reproduce.returncode == 0, reproduce.stderr
    assert 'numbers within tolerance' in reproduce.stdout
    # analyze needs no scipy either: its import was most of a whole run's time.
    analyze = lumpbeam('analyze', str(small_bag), blocked=(*OPTIONAL, 'scipy'))
    assert analyze.returncode == 0, analyze.stderr
    assert 'status: OK' in analyze.stdout
    assert analyze.stdout.rstrip().endswith("loaded: ['mcap', 'numpy', 'rosbags', 'yaml']")


@pytest.mark.parametrize(
    ('arguments', 'blocked', 'message'),
    [
        (
            ['track', '{bag}', '{tmp}/out'],
            'cv2',
            "needs OpenCV: pip install 'lumpbeam_ros[vision]'",
        ),
        (['play', '{bag}'], 'rclpy', "needs ROS 2 (rclpy): pip install 'lumpbeam_ros[ros]'"),
        (
            ['analyze', '{bag}', '--plots', '{tmp}/plots'],
            'matplotlib',
            "needs matplotlib: pip install 'lumpbeam_ros[plots]'",
        ),
    ],
    ids=['track-cv2', 'play-rclpy', 'analyze-plots-matplotlib'],
)
def test_a_missing_optional_package_is_one_line_and_exit_2(
    small_bag, tmp_path, arguments, blocked, message
):
    filled = [a.format(bag=small_bag, tmp=tmp_path) for a in arguments]
    result = lumpbeam(*filled, blocked=(blocked,))
    assert result.returncode == 2
    assert result.stderr == f'lumpbeam {arguments[0]} {message}\n'


def test_a_missing_core_module_is_a_broken_install_not_a_hint():
    result = lumpbeam('reproduce', blocked=('numpy',))
    assert result.returncode == 1
    assert "ModuleNotFoundError: No module named 'numpy" in result.stderr


#: One path component longer than any file system allows (255 bytes).
LONG = 'a' * 300


@pytest.mark.parametrize(
    'argv',
    [
        ['synth', '{long}', '--duration', '3'],
        ['track', '{bag}', '{long}'],
        ['analyze', '{long}'],
        ['diagnose', '{long}'],
        ['compare', '{long}'],
        ['record', '{long}', '/tip_pose'],
        ['repair', '{long}'],
        ['repair', '{bag}', '{long}'],
        ['doctor', '{long}'],
        ['play', '{long}'],
        ['view', '--bag', '{long}', '--port', '0'],
        ['campaign', '{long}', '--out', '{tmp}/results'],
    ],
    ids=lambda argv: ' '.join(argv[:2]),
)
def test_a_path_the_system_refuses_is_one_line(argv, small_bag, tmp_path, capsys, monkeypatch):
    from lumpbeam_ros.apps.cli.main import main

    monkeypatch.chdir(tmp_path)
    args = [a.format(long=LONG, bag=small_bag, tmp=tmp_path) for a in argv]
    assert main(args) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith(f'lumpbeam {argv[0]}: error: ') and '\n' not in err
    assert LONG in err and 'too long' in err.lower()


def test_sigterm_interrupts_a_command_as_ctrl_c_does(tmp_path):
    """`synth` stopped by SIGTERM while it writes (frames): exit 143, one line, no partial bag."""
    import signal
    import time

    out = tmp_path / 'long'
    process = subprocess.Popen(
        [
            sys.executable,
            '-m',
            'lumpbeam_ros.apps.cli.main',
            'synth',
            str(out),
            '--duration',
            '4',
            '--rate',
            '30',
            '--images',
            '--image-size',
            '320x240',
        ],  # fmt: skip
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    while not out.exists() and process.poll() is None:
        time.sleep(0.05)  # the simulation is done, the writing has begun
    process.send_signal(signal.SIGTERM)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 128 + signal.SIGTERM, stderr
    assert stderr.strip() == 'lumpbeam synth: interrupted'
    assert not out.exists()
