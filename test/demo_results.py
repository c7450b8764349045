"""One run of ``lumpbeam demo`` per test session, shared by every test that reads its results.

The demo brings up the whole live graph (player, recorder, simulator, identifier, diagnosis
node) and is the costliest thing the suite does; the end-to-end demo test and the layout
checks read the same results instead of each running the graph. Under pytest-xdist every
worker is its own process, so the first worker that asks runs the demo under a file lock in
the session's shared temporary folder and the others read what it left there.
"""

from __future__ import annotations

import contextlib
import fcntl
import io
import json
from dataclasses import dataclass
from pathlib import Path

import pytest

from lumpbeam_ros.apps.cli.main import main

#: The demo's options: 7 s of synthetic drop test (release at 2 s) without camera frames,
#: with the demo's default hidden effect (a 15 ms camera latency) for the live diagnosis.
DEMO_ARGS = ('--duration', '7', '--no-images')
DURATION_S = 7


@dataclass(frozen=True)
class DemoResults:
    """What one demo run left: its folder, its summary, what it printed and its exit code."""

    out: Path
    summary: dict
    printed: str
    exit_code: int


def _run(folder: Path) -> None:
    out = folder / 'results'
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        code = main(['demo', '--out', str(out), *DEMO_ARGS, '--json', str(folder / 's.json')])
    (folder / 'printed.txt').write_text(printed.getvalue())
    (folder / 'exit_code').write_text(str(code))


@pytest.fixture(scope='session')
def demo_results(tmp_path_factory, worker_id) -> DemoResults:
    """The results of the session's one demo run (run on first use, under a file lock)."""
    shared = tmp_path_factory.getbasetemp()
    if worker_id != 'master':
        shared = shared.parent  # the folder every xdist worker's basetemp sits in
    folder = shared / 'demo_results'
    folder.mkdir(exist_ok=True)
    with (folder.parent / 'demo_results.lock').open('w') as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not (folder / 'exit_code').is_file():
            _run(folder)
    code = int((folder / 'exit_code').read_text())
    out = folder / 'results'
    summary_file = out / 'summary.json'
    summary = json.loads(summary_file.read_text()) if summary_file.is_file() else {}
    return DemoResults(out, summary, (folder / 'printed.txt').read_text(), code)
