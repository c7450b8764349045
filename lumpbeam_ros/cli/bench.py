"""``lumpbeam bench``: the benchmarks, each as a ratio against a same-run baseline."""

from __future__ import annotations

import argparse

from lumpbeam_lab.bench.runner import available_suites, format_table, run_suites
from lumpbeam_ros.cli.output import write_json
from lumpbeam_ros.errors import LumpbeamError


def run(args: argparse.Namespace) -> int:
    """Runs the chosen suites and prints their table."""
    suites = available_suites()
    chosen = args.only or suites
    unknown = [name for name in chosen if name not in suites]
    if unknown:
        raise LumpbeamError(f'unknown suite {unknown[0]!r}; choose from {", ".join(suites)}')
    results = run_suites(chosen, quick=args.quick)
    print(format_table(results))
    if args.json:
        write_json(args.json, {'results': [r.as_dict() for r in results]})
    return 0
