"""Runs the benchmark suites and formats their results."""

from __future__ import annotations

import importlib
import importlib.util
from collections.abc import Iterable

from lumpbeam_lab.bench.bench_result import BenchResult

#: Suite modules under :mod:`lumpbeam_lab.bench`.
SUITES = (
    'model',
    'tracker',
    'camera-accuracy',
    'ident',
    'crb',
    'records',
    'bagio',
    'diagnose',
    'diagnose_pairs',
    'campaign',
    'cli',
    'live_graph',
    'shaping',
    'arm',
)


def _module(suite: str) -> str:
    """The module of a suite (suite names use hyphens, modules underscores)."""
    return f'lumpbeam_lab.bench.{suite.replace("-", "_")}'


def available_suites() -> list[str]:
    """Returns the suites that exist in this build.

    None is imported: a suite's dependencies load only when it runs (``--only cli`` needs no
    OpenCV).
    """
    return [name for name in SUITES if importlib.util.find_spec(_module(name))]


def run_suites(names: Iterable[str], quick: bool = False) -> list[BenchResult]:
    """Runs suites in order.

    Args:
        names: Suite names from :func:`available_suites`.
        quick: Smaller inputs, for tests of the benchmark code itself.

    Returns:
        All results, suite by suite.
    """
    results: list[BenchResult] = []
    for name in names:
        module = importlib.import_module(_module(name))
        results.extend(module.run(quick=quick))
    return results


def format_table(results: Iterable[BenchResult]) -> str:
    """Formats results as an aligned text table, one row per benchmark.

    Args:
        results: Benchmark results.

    Returns:
        The table, with details on indented lines below their row; the diagnosis cases
        (results with a ``case`` detail) in their own table after it.
    """
    results = list(results)
    cases = [r for r in results if 'case' in r.details]
    results = [r for r in results if 'case' not in r.details]
    lines = [f'{"benchmark":<34} {"value":>12} {"baseline":>12}  {"ratio":>8}  unit / baseline']
    for r in results:
        # A ratio below 0.1 (a cost counted in baselines) keeps two significant digits.
        ratio = f'{r.ratio:>7.1f}' if r.ratio >= 0.1 else f'{r.ratio:>7.2g}'
        lines.append(
            f'{r.name:<34} {r.value:>12.4g} {r.baseline_value:>12.4g}  {ratio}x  '
            f'{r.unit} / {r.baseline}'
        )
        for key, value in r.details.items():
            shown = f'{value:.4g}' if isinstance(value, float) else str(value)
            lines.append(f'    {key}: {shown}')
    if cases:
        from lumpbeam_lab.bench.diagnose_pairs import format_cases

        lines = ([*lines, ''] if results else []) + [format_cases(cases)]
    return '\n'.join(lines)
