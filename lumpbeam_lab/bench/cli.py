"""CLI start-up: ``lumpbeam --help`` against the interpreter's own start (``python -c pass``).

Both run as fresh processes of the same interpreter with the same environment, alternated so
that a busy moment slows both; the figure is the median wall time of each. What the CLI adds
over the bare interpreter is its own import cost, which the help must keep small: every
subcommand's dependencies are imported only when it runs (:mod:`lumpbeam_ros.cli.main`).
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import time

from lumpbeam_lab.bench.bench_result import BenchResult

#: What the ``lumpbeam`` console script runs.
ENTRY_POINT = 'import sys; from lumpbeam_ros.cli.script import lumpbeam; sys.exit(lumpbeam())'
BASELINE = 'python -c pass'
#: The start-up a user should not notice, s.
BUDGET_S = 0.3


def _wall_time(command: list[str]) -> float:
    """Runs a command to completion with its output discarded; returns its wall time, s."""
    start = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start


def start_time(arguments: list[str], runs: int) -> BenchResult:
    """The median start-to-exit time of ``lumpbeam ARGUMENTS`` against ``python -c pass``.

    Args:
        arguments: The command line after ``lumpbeam``, e.g. ``['--help']``.
        runs: Processes of each kind (medians of this many).

    Returns:
        The result; ``ratio`` is the baseline over the CLI (below 1: the CLI is slower).
    """
    cli, bare = [], []
    for _ in range(runs):
        cli.append(_wall_time([sys.executable, '-c', ENTRY_POINT, *arguments]))
        bare.append(_wall_time([sys.executable, '-c', 'pass']))
    value, baseline = statistics.median(cli), statistics.median(bare)
    return BenchResult(
        name='cli_start_' + '_'.join(a.strip('-') for a in arguments),
        value=value,
        unit='s',
        baseline=BASELINE,
        baseline_value=baseline,
        ratio=baseline / value,
        details={
            'command': ' '.join(['lumpbeam', *arguments]),
            'runs': runs,
            'cli_own_s': value - baseline,
            'max_s': max(cli),
            'budget_s': BUDGET_S,
        },
    )


def run(quick: bool = False) -> list[BenchResult]:
    """Runs the CLI start-up suite.

    Args:
        quick: 3 processes of each kind instead of 15.

    Returns:
        ``lumpbeam --help``, then ``lumpbeam analyze --help``.
    """
    runs = 3 if quick else 15
    return [start_time(['--help'], runs), start_time(['analyze', '--help'], runs)]
