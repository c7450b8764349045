"""CLI start-up: ``lumpbeam --help`` against the interpreter's own start (``python -c pass``).

Both run as fresh processes of the same interpreter with the same environment, alternated so
that a busy moment slows both; the figure is the median wall time of each. What the CLI adds
over the bare interpreter is its own import cost, which the help must keep small: every
subcommand's dependencies are imported only when it runs (:mod:`lumpbeam_ros.apps.cli.main`).

``cli_start_analyze_12s_bag`` is a whole ``lumpbeam analyze`` of a synthetic 12 s, 180 Hz
drop-test bag, as a process: its imports, reading the bag, the identification and the
summary, against the same bare interpreter (target 0.5 s).
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from lumpbeam_lab.bench.bench_result import BenchResult

#: What the ``lumpbeam`` console script runs.
ENTRY_POINT = 'import sys; from lumpbeam_ros.apps.cli.script import lumpbeam; sys.exit(lumpbeam())'
BASELINE = 'python -c pass'
#: The start-up a user should not notice, s.
BUDGET_S = 0.3
#: A whole ``lumpbeam analyze`` of a 12 s bag, s.
ANALYZE_BUDGET_S = 0.5


def _wall_time(command: list[str]) -> float:
    """Runs a command to completion with its output discarded; returns its wall time, s."""
    start = time.perf_counter()
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start


def start_time(
    arguments: list[str],
    runs: int,
    name: str | None = None,
    shown: str | None = None,
    budget_s: float = BUDGET_S,
) -> BenchResult:
    """The median start-to-exit time of ``lumpbeam ARGUMENTS`` against ``python -c pass``.

    Args:
        arguments: The command line after ``lumpbeam``, e.g. ``['--help']``.
        runs: Processes of each kind (medians of this many).
        name: The row's name (default: from the arguments).
        shown: The command as the row shows it (default: the command line).
        budget_s: The target, s.

    Returns:
        The result; ``ratio`` is the baseline over the CLI (below 1: the CLI is slower).
    """
    cli, bare = [], []
    for _ in range(runs):
        cli.append(_wall_time([sys.executable, '-c', ENTRY_POINT, *arguments]))
        bare.append(_wall_time([sys.executable, '-c', 'pass']))
    value, baseline = statistics.median(cli), statistics.median(bare)
    return BenchResult(
        name=name or 'cli_start_' + '_'.join(a.strip('-') for a in arguments),
        value=value,
        unit='s',
        baseline=BASELINE,
        baseline_value=baseline,
        ratio=baseline / value,
        details={
            'command': shown or ' '.join(['lumpbeam', *arguments]),
            'runs': runs,
            'cli_own_s': value - baseline,
            'max_s': max(cli),
            'budget_s': budget_s,
        },
    )


def analyze_time(runs: int, duration_s: float = 12.0) -> BenchResult:
    """``lumpbeam analyze`` of a synthetic drop-test bag, whole process, against the bare start.

    Args:
        runs: Processes of each kind.
        duration_s: The bag's length, s.

    Returns:
        The ``cli_start_analyze_<duration>s_bag`` row.
    """
    from lumpbeam_ros.core.model.parameters import DropTestConfig, load_beam_config
    from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, write_drop_test_bag

    beam, _ = load_beam_config()
    with tempfile.TemporaryDirectory(prefix='lumpbeam-bench-') as tmp:
        bag = Path(tmp) / 'drop'
        options = SynthOptions(duration_s=duration_s, markers_rate_hz=0.0)
        write_drop_test_bag(bag, beam, DropTestConfig(duration_s=duration_s), options)
        return start_time(
            ['analyze', str(bag)],
            runs,
            name=f'cli_start_analyze_{duration_s:g}s_bag',
            shown=f'lumpbeam analyze BAG ({duration_s:g} s, 180 Hz)',
            budget_s=ANALYZE_BUDGET_S,
        )


def run(quick: bool = False) -> list[BenchResult]:
    """Runs the CLI start-up suite.

    Args:
        quick: 3 processes of each kind instead of 15, and no bag analyzed (its test runs
            :func:`analyze_time`).

    Returns:
        ``lumpbeam --help``, ``lumpbeam analyze --help``, then ``lumpbeam analyze BAG``.
    """
    runs = 3 if quick else 15
    rows = [start_time(['--help'], runs), start_time(['analyze', '--help'], runs)]
    return rows if quick else [*rows, analyze_time(runs)]
