"""Diagnosis of hidden pairs: forward selection against fitting every combination.

One row per case, each a synthetic 12 s, 180 Hz drop-test bag (20 um of pose noise) with
effects hidden in it: four pairs, one single effect (dry friction, the slowest to
simulate) and the nominal beam over 20 noise seeds.

- value: CPU seconds (``time.process_time``, one core: BLAS runs single-threaded) of
  ``read_record`` + ``diagnose``; for the nominal row the mean over the seeds.
- allowed: the budget, 10 s for one effect (and for none), 30 s for a pair.
- baseline: the same diagnosis with ``exhaustive=True``: every single effect and every pair
  of the library (8 + 28 fits) fitted from scratch, in the same run (for the nominal row, on
  its first seed); the ratio is how many times faster the forward selection is.
- found: the names in the order chosen; worst parameter error: the largest relative error
  of the named effects' parameters against the hidden values (``-`` when nothing is named).
"""

from __future__ import annotations

import tempfile
import time
from collections.abc import Mapping
from pathlib import Path

from lumpbeam_lab.bench.bench_result import BenchResult
from lumpbeam_ros.core.diagnose.measurement import read_record
from lumpbeam_ros.core.diagnose.workflow import Diagnosis, diagnose
from lumpbeam_ros.core.model.parameters import EFFECT_PARAMETERS, load_beam_config
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, write_drop_test_bag

#: Hidden effects of each case, with realistic strengths.
CASES: tuple[dict[str, float], ...] = (
    {'base_compliance': 2e4, 'quadratic_drag': 0.5},
    {'coulomb_friction': 1.0, 'sensor_latency': 0.015},
    {'added_mass': 0.3, 'sensor_scale': 1.05},
    {'cubic_stiffness': 1e8, 'coulomb_friction': 1.0},
    {'coulomb_friction': 1.0},
)

#: CPU budget per 12 s bag, s: one effect (or none), a pair.
ALLOWED_S = {1: 10.0, 2: 30.0}

NOMINAL_SEEDS = 20


def diagnose_bag(
    effects: Mapping[str, float], seed: int, duration_s: float, exhaustive: bool = False
) -> tuple[float, Diagnosis]:
    """CPU seconds of reading and diagnosing one synthetic bag, and the diagnosis."""
    beam, drop = load_beam_config()
    options = SynthOptions(
        duration_s=duration_s, seed=seed, effects=dict(effects), markers_rate_hz=0.0
    )
    with tempfile.TemporaryDirectory(prefix='lumpbeam-bench-') as tmp:
        bag = Path(tmp) / 'drop'
        write_drop_test_bag(bag, beam, drop, options)
        start = time.process_time()
        result = diagnose(read_record(bag), beam, exhaustive=exhaustive)
        return time.process_time() - start, result


def worst_error(result: Diagnosis, hidden: Mapping[str, float]) -> float:
    """Largest relative parameter error of the named effects (NaN when none is named).

    Args:
        result: The diagnosis.
        hidden: The hidden effects and their values.

    Returns:
        The error; infinite when a named effect was not hidden.
    """
    errors = []
    for effect in result.missing_effects:
        if effect.name not in hidden:
            return float('inf')
        true = hidden[effect.name]
        found = effect.parameters[EFFECT_PARAMETERS[effect.name]]
        # sensor_scale is off at 1: its error is relative to the departure from 1.
        off = 1.0 if effect.name == 'sensor_scale' else 0.0
        errors.append(abs(found - true) / abs(true - off))
    return max(errors) if errors else float('nan')


def found(result: Diagnosis) -> str:
    """The named effects joined by ``+`` in the order chosen (or the verdict if none)."""
    return '+'.join(e.name for e in result.missing_effects) or result.missing_effect


def _case(hidden: Mapping[str, float], seed: int, duration_s: float) -> BenchResult:
    cpu, result = diagnose_bag(hidden, seed, duration_s)
    baseline, _ = diagnose_bag(hidden, seed, duration_s, exhaustive=True)
    return BenchResult(
        name=f'diagnose_{"+".join(hidden)}',
        value=cpu,
        unit='CPU s',
        baseline='every combination of effects fitted from scratch',
        baseline_value=baseline,
        ratio=baseline / cpu,
        details={
            'case': '+'.join(hidden),
            'allowed_s': ALLOWED_S[len(hidden)],
            'found': found(result),
            'worst_parameter_error': worst_error(result, hidden),
            'confidence': result.confidence,
        },
    )


def _nominal(seeds: int, duration_s: float) -> BenchResult:
    runs = [diagnose_bag({}, 100 + seed, duration_s) for seed in range(seeds)]
    baseline, _ = diagnose_bag({}, 100, duration_s, exhaustive=True)
    nones = sum(r.missing_effect == 'none' for _, r in runs)
    mean = sum(cpu for cpu, _ in runs) / seeds
    return BenchResult(
        name=f'diagnose_nominal_x{seeds}',
        value=mean,
        unit='CPU s',
        baseline='every combination of effects fitted from scratch',
        baseline_value=baseline,
        ratio=baseline / runs[0][0],
        details={
            'case': f'nominal x {seeds} seeds',
            'allowed_s': ALLOWED_S[1],
            'found': f'none {nones} of {seeds}',
            'worst_parameter_error': float('nan'),
            'others': ','.join(sorted({r.missing_effect for _, r in runs} - {'none'})),
        },
    )


def run(quick: bool = False) -> list[BenchResult]:
    """Runs every case.

    Args:
        quick: One pair and two nominal seeds on 6 s records (the benchmark's own test).

    Returns:
        One result per case, the nominal seeds last.
    """
    if quick:
        return [_case(CASES[0], 1, 6.0), _nominal(2, 6.0)]
    return [_case(hidden, i + 1, 12.0) for i, hidden in enumerate(CASES)] + [
        _nominal(NOMINAL_SEEDS, 12.0)
    ]


def format_cases(results: list[BenchResult]) -> str:
    """The case table: case, CPU s, allowed, vs exhaustive, found, worst parameter error.

    Args:
        results: Results of :func:`run`.

    Returns:
        The table.
    """
    lines = [
        f'{"case":<35} {"CPU s":>5} {"allowed":>7} {"vs exhaustive":>13}  {"found":<34} '
        f'{"worst param error":>17}'
    ]
    for r in results:
        d = r.details
        error = d['worst_parameter_error']
        shown = '-' if error != error else f'{100.0 * error:.2f} %'
        lines.append(
            f'{d["case"]:<35} {r.value:>5.1f} {d["allowed_s"]:>7.0f} {r.ratio:>12.1f}x  '
            f'{d["found"]:<34} {shown:>17}'
        )
    return '\n'.join(lines)
