"""``lumpbeam bench``: the benchmarks, each as a ratio against a same-run baseline."""

from __future__ import annotations

import argparse
import importlib
import sys
from pathlib import Path
from types import ModuleType

from lumpbeam_ros.apps.cli.output import write_json
from lumpbeam_ros.base.errors import LumpbeamError

#: Where the benchmarks live: the repository's ``lumpbeam_lab/``, beside the package.
LAB = 'lumpbeam_lab'


def lab_runner(checkout: Path | None = None) -> ModuleType:
    """The lab's bench runner, from the checkout this package was installed from.

    The lab is not installed with the product (what proves it is kept apart from what users
    run); an editable install or a source tree has it beside ``lumpbeam_ros/``.

    Args:
        checkout: Where to look for the lab (default: the folder above this package).

    Raises:
        LumpbeamError: The package was installed without its repository (a wheel).
    """
    checkout = Path(__file__).resolve().parents[3] if checkout is None else checkout
    if (checkout / LAB / '__init__.py').is_file() and str(checkout) not in sys.path:
        sys.path.append(str(checkout))
    try:
        return importlib.import_module(f'{LAB}.bench.runner')
    except ModuleNotFoundError as exc:
        if exc.name is None or not exc.name.startswith(LAB):
            raise
        raise LumpbeamError(
            f'the benchmarks are not installed with the package: they live in the {LAB}/ '
            'folder of the lumpbeam_ros repository; run `lumpbeam bench` (or `make bench`) '
            'from a checkout of it'
        ) from None


def run(args: argparse.Namespace) -> int:
    """Runs the chosen suites and prints their table."""
    runner = lab_runner()
    available_suites, format_table, run_suites = (
        runner.available_suites,
        runner.format_table,
        runner.run_suites,
    )
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
