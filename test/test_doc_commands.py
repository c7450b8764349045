"""Every shell block of README.md and doc/*.md runs as written, in a fresh folder.

The blocks of one page run in order in one empty folder (a later block reads what an earlier
one wrote, as a reader following the page would), with the package's ``lumpbeam`` first on
``PATH`` and no checkout around: ``config/...`` and ``examples/...`` are found by name in the
installed package. Each block must exit 0 and leave the files it names. A block this test
does not run is listed in :data:`RUN_ELSEWHERE` with the test that runs it or the reason, so
a new block on a page fails here until it is either runnable or listed.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

from lumpbeam_ros.apps.cli.main import build_parser

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / 'README.md', *sorted((ROOT / 'doc').glob('*.md'))]
BLOCK = re.compile(r'^```bash\n(.*?)^```', re.M | re.S)

#: Blocks not run here, by their first command: where they are run, or why not.
RUN_ELSEWHERE = {
    'make demo': 'the bootstrap itself: CI runs `make test` on a fresh clone',
    'lumpbeam view --bag': 'serves until stopped: test/apps/cli/test_view.py',
    'lumpbeam launch launch/drop_test.launch.yaml': 'runs until stopped: test_launch.py',
    'identifier_node --ros-args': 'a node that spins until stopped: test/nodes',
    'lumpbeam record results/rec': 'a recorder beside a player in a second shell: test_record.py',
    'pip install .': 'installs into the environment: test_setup.py builds and installs the wheel',
    'mkdir -p ~/ws/src': "a colcon workspace in the user's home: test_setup.py runs colcon",
    'make test': 'the developer commands that run this very suite',
    'shaper_node --ros-args': 'a node that spins until stopped: test/nodes/test_shaper_node.py',
    'pytest test/core/shaping/test_on_arm.py': 'a slow test of the suite itself',
    'lumpbeam demo --arm': 'test/apps/demo/test_arm_loop.py runs the same command',
}

#: The parsed arguments that name a file or folder a command writes.
WRITTEN = ('out', 'output', 'json', 'plots', 'write_model')


def _blocks(page: Path) -> list[str]:
    return [m.group(1) for m in BLOCK.finditer(page.read_text(encoding='utf-8'))]


def _commands(block: str) -> list[str]:
    """The block's commands: continuation lines joined, comments and blank lines dropped."""
    joined = re.sub(r'\\\n\s*', ' ', block)
    return [line.split('  #')[0].strip() for line in joined.splitlines() if line.strip()]


def _listed(block: str) -> str | None:
    first = _commands(block)[0]
    return next((why for start, why in RUN_ELSEWHERE.items() if first.startswith(start)), None)


def _written(command: str) -> list[str]:
    """What a ``lumpbeam`` command writes, as the command line's own parser reads it."""
    words = shlex.split(command)
    if words[:1] != ['lumpbeam']:
        return []
    args = vars(build_parser().parse_args(words[1:]))
    return [str(args[name]) for name in WRITTEN if args.get(name)]


def _runnable(page: Path) -> list[str]:
    return [block for block in _blocks(page) if _listed(block) is None]


@pytest.mark.parametrize('page', PAGES, ids=lambda p: p.name)
def test_every_block_is_run_here_or_says_where(page):
    for block in _blocks(page):
        if _listed(block) is None:
            assert _commands(block), f'{page.name}: an empty shell block'


def test_the_pages_have_blocks_this_test_runs():
    runnable = {page.name: len(_runnable(page)) for page in PAGES}
    assert runnable['README.md'] >= 6 and runnable['shaping.md'] >= 3, runnable


def test_what_a_command_writes_is_read_from_its_options():
    assert _written('lumpbeam analyze b --json r/a.json --plots r/figs') == ['r/a.json', 'r/figs']
    assert _written('lumpbeam synth r/film --duration 4 --image-size 640x480') == ['r/film']
    assert _written('lumpbeam shape m.csv s.csv --params p.json') == ['s.csv']
    assert _written("lumpbeam campaign 'r/c/*' --out r/campaign --workers 2") == ['r/campaign']


@pytest.mark.slow
@pytest.mark.parametrize(
    'page', [p for p in PAGES if _runnable(p)], ids=lambda p: p.name
)  # fmt: skip
def test_the_pages_commands_run_as_written_in_a_fresh_folder(page, tmp_path):
    env = {
        **os.environ,
        'PATH': f'{Path(sys.executable).parent}{os.pathsep}{os.environ.get("PATH", "")}',
        'MPLBACKEND': 'Agg',
    }
    for block in _runnable(page):
        commands = [c for c in _commands(block) if not c.startswith('source ')]
        script = '\n'.join(['set -euo pipefail', *commands])
        done = subprocess.run(
            ['bash', '-c', script], cwd=tmp_path, env=env, capture_output=True, text=True,
            timeout=600, check=False,
        )  # fmt: skip
        assert done.returncode == 0, f'{page.name}:\n{block}\n{done.stdout}\n{done.stderr}'
        for command in commands:
            for path in _written(command):
                written = tmp_path / path
                assert written.exists(), f'{page.name}: `{command}` left no {path}'
                if written.is_dir():
                    assert any(written.iterdir()), f'{page.name}: `{command}`: {path} is empty'
