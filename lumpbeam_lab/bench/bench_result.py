"""The result record of one benchmark (doc/interfaces.md, 'Command line', ``bench`` JSON keys)."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import Any


@dataclass(frozen=True)
class BenchResult:
    """One measured figure beside its baseline.

    Attributes:
        name: What was measured, e.g. ``'simulate_drop_test_ns10'``.
        value: The project's figure.
        unit: Unit of ``value`` and ``baseline_value``.
        baseline: What the baseline is, e.g. ``"solve_ivp(method='Radau')"``.
        baseline_value: The baseline's figure, same unit.
        ratio: How many times better the project is (>1 is better), whatever the unit's
            direction.
        details: Further figures (accuracy, sizes) worth printing.
    """

    name: str
    value: float
    unit: str
    baseline: str
    baseline_value: float
    ratio: float
    details: dict[str, Any] = field(default_factory=dict)

    def as_dict(self) -> dict[str, Any]:
        """Returns the JSON form."""
        return asdict(self)


def best_time(
    function: Callable[[], Any],
    repeat: int = 3,
    clock: Callable[[], float] = time.perf_counter,
) -> tuple[float, Any]:
    """Times a call, keeping the fastest of ``repeat`` runs (the least disturbed one).

    Args:
        function: What to time.
        repeat: Number of runs.
        clock: Wall time (default) or ``time.process_time`` for CPU time.

    Returns:
        The best wall time in seconds and the last run's return value.
    """
    best = float('inf')
    value = None
    for _ in range(max(1, repeat)):
        start = clock()
        value = function()
        best = min(best, clock() - start)
    return best, value
