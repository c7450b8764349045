"""Diagnosis speed: a 12 s, 180 Hz drop-test bag diagnosed end to end.

- ``diagnose_bag_12s_180hz``: wall time of ``read_record`` + ``diagnose`` (every candidate
  fitted, scored, the winner refit) on a synthetic bag with dry friction hidden in it, the
  effect whose simulation is the slowest (the solver steps the stick-slip decision).
  Baseline: the same fits driven by the Radau reference integrator
  (:func:`~lumpbeam_ros.core.model.integrate.solve_reference`) instead of the modal solver. A full
  diagnosis that way would take the better part of an hour, so the baseline is extrapolated:
  one Radau simulation of the nominal beam (no effects, its easiest case) is timed on a
  shortened record, scaled linearly to the record's length and multiplied by the number of
  simulations the diagnosis ran. That understates the baseline: friction and drag make the
  equations stiffer for Radau, and the extrapolation ignores the fits' overhead.
- ``diagnose_cpu_<effects>``: CPU seconds (one core) of ``read_record`` + ``diagnose`` of a
  bag with one effect (dry friction, the slowest to simulate) and with a pair (the slowest
  pair of ``diagnose_pairs``), against the CPU of one simulation of the nominal beam at the
  same bag's stamps, measured in the same run: the ratio is the diagnosis's cost in
  simulations (inverted). The target is 2 CPU s for one effect and 6 for a pair.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

from lumpbeam_lab.bench.bench_result import BenchResult, best_time
from lumpbeam_lab.bench.diagnose_pairs import diagnose_bag, found, worst_error
from lumpbeam_ros.base.blas import single_threaded_blas
from lumpbeam_ros.core.diagnose.measurement import Record, read_record
from lumpbeam_ros.core.diagnose.workflow import diagnose, nominal_form
from lumpbeam_ros.core.model.chain import LumpedChain
from lumpbeam_ros.core.model.integrate import ChainState, solve_reference
from lumpbeam_ros.core.model.parameters import BeamParameters, DropTestConfig, load_beam_config
from lumpbeam_ros.core.model.simulate import simulate_loads
from lumpbeam_ros.core.model.statics import static_equilibrium
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, write_drop_test_bag

BUDGET_S = 60.0
HIDDEN = {'coulomb_friction': 1.0}

#: The CPU rows: hidden effects and the CPU seconds a 12 s bag may take.
CPU_CASES: tuple[tuple[dict[str, float], float], ...] = (
    (HIDDEN, 2.0),
    ({'cubic_stiffness': 1e8, 'coulomb_friction': 1.0}, 6.0),
)

#: Radau tolerances that match the modal solver's accuracy (sub-micrometre at the tip).
RADAU_RTOL = 1e-8
RADAU_ATOL = 1e-10


def _radau_per_simulation(
    beam: BeamParameters, drop: DropTestConfig, t: np.ndarray, span_s: float
) -> tuple[float, float]:
    """Seconds per simulation of the whole record by Radau, extrapolated from ``span_s``.

    Returns:
        The extrapolated time and the largest tip-z difference from the modal solver
        over the measured span, m.
    """
    loaded = LumpedChain.from_beam(beam, drop.load_kg)
    free = LumpedChain.from_beam(beam, 0.0)
    state = ChainState(static_equilibrium(loaded), np.zeros(beam.n_segments))
    grid = t[(t >= drop.release_time_s) & (t <= drop.release_time_s + span_s)]

    def run() -> np.ndarray:
        return solve_reference(free, state, grid, rtol=RADAU_RTOL, atol=RADAU_ATOL).phi

    seconds, phi = best_time(run, repeat=1)
    # From the start of the record, so the modal run sees the drop too.
    modal = simulate_loads(beam, t[t <= grid[-1]], [(drop.release_time_s, 0.0)], drop.load_kg)
    difference = float(np.max(np.abs(free.tip_pose(phi)[1] - modal.z[-grid.size :])))
    return seconds * (t[-1] - drop.release_time_s) / span_s, difference


def _modal_per_simulation(beam: BeamParameters, drop: DropTestConfig, t: np.ndarray) -> float:
    seconds, _ = best_time(
        lambda: simulate_loads(beam, t, [(drop.release_time_s, 0.0)], drop.load_kg), repeat=3
    )
    return seconds


def _simulation_cpu(record: Record, beam: BeamParameters, repeat: int = 5) -> float:
    """CPU seconds of one simulation of the nominal beam at a record's stamps (the best run).

    Single-threaded BLAS, as the diagnosis runs.
    """
    nominal = nominal_form(beam)
    best = float('inf')
    with single_threaded_blas():
        for _ in range(repeat):
            start = time.process_time()
            simulate_loads(nominal, record.t, record.load_events, record.initial_load_kg)
            best = min(best, time.process_time() - start)
    return best


def cpu_row(
    hidden: dict[str, float], allowed_s: float, seed: int, duration_s: float
) -> BenchResult:
    """The CPU of one diagnosis against one nominal simulation of the same bag.

    Args:
        hidden: The effects hidden in the bag.
        allowed_s: The target, CPU s.
        seed: Noise seed.
        duration_s: Record length, s.

    Returns:
        The result (``ratio``: one simulation's CPU over the diagnosis's).
    """
    cpu, result = diagnose_bag(hidden, seed, duration_s)
    beam, _ = load_beam_config()
    simulation = _simulation_cpu(result.record, beam)
    return BenchResult(
        name=f'diagnose_cpu_{"+".join(hidden)}',
        value=cpu,
        unit='CPU s',
        baseline="one simulation of the nominal beam at the bag's stamps",
        baseline_value=simulation,
        ratio=simulation / cpu,
        details={
            'allowed_cpu_s': allowed_s,
            'within': cpu <= allowed_s,
            'cost_in_simulations': cpu / simulation,
            'simulations': result.simulations,
            'found': found(result),
            'worst_parameter_error': worst_error(result, hidden),
        },
    )


def run(quick: bool = False) -> list[BenchResult]:
    """Runs the diagnosis benchmark.

    Args:
        quick: The Radau row only, on a 4 s record with a shorter Radau span (the
            benchmark's own test; the CPU rows' test calls :func:`cpu_row`).

    Returns:
        The diagnosis wall time against the extrapolated Radau-driven one, then the CPU
        rows of one effect and of a pair.
    """
    if quick:
        return [_radau_row(quick)]
    return [_radau_row(quick)] + [
        cpu_row(hidden, allowed, 1 + i, 12.0) for i, (hidden, allowed) in enumerate(CPU_CASES)
    ]


def _radau_row(quick: bool) -> BenchResult:
    beam, _ = load_beam_config()
    duration = 4.0 if quick else 12.0
    drop = DropTestConfig(duration_s=duration)
    options = SynthOptions(duration_s=duration, seed=11, effects=HIDDEN)
    with tempfile.TemporaryDirectory(prefix='lumpbeam-bench-') as tmp:
        bag = Path(tmp) / 'drop'
        write_drop_test_bag(bag, beam, drop, options)
        start = time.perf_counter()
        result = diagnose(read_record(bag), beam)
        ours = time.perf_counter() - start
    t = result.record.t
    radau, difference = _radau_per_simulation(beam, drop, t, 0.25 if quick else 1.0)
    modal = _modal_per_simulation(beam, drop, t)
    baseline = radau * result.simulations
    torque = result.effect_parameters.get('torque_nm', float('nan'))
    return BenchResult(
        name=f'diagnose_bag_{duration:g}s_180hz',
        value=ours,
        unit='s',
        baseline='same fits driven by Radau (solve_reference), extrapolated',
        baseline_value=baseline,
        ratio=baseline / ours,
        details={
            'budget_s': BUDGET_S,
            'within_budget': ours < BUDGET_S,
            'hidden_effect': 'coulomb_friction=1.0 N m',
            'missing_effect_found': result.missing_effect,
            'torque_nm_found': torque,
            'gap_rms_before_um': result.gap_before.rms_m * 1e6,
            'gap_rms_after_um': result.gap_after.rms_m * 1e6,
            'simulations': result.simulations,
            'modal_ms_per_simulation_nominal': modal * 1e3,
            'radau_ms_per_simulation_nominal': radau * 1e3,
            'radau_vs_modal_max_dz_um': difference * 1e6,
        },
    )
