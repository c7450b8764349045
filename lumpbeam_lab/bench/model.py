"""Model benchmarks: the drop-test simulation against ``solve_ivp(method='Radau')``.

The baseline integrates the same equations (B.16, :func:`~lumpbeam_ros.core.model.integrate.
solve_reference`) at ``rtol = 1e-6``: the loosest tolerance whose tip agrees with a
``rtol = 1e-10`` run to 0.1 um, i.e. the cheapest Radau run as accurate as the project's.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from lumpbeam_lab.bench.bench_result import BenchResult, best_time
from lumpbeam_ros.core.model.chain import LumpedChain
from lumpbeam_ros.core.model.integrate import ChainState, solve_reference
from lumpbeam_ros.core.model.parameters import BeamParameters, DropTestConfig
from lumpbeam_ros.core.model.simulate import simulate_drop_test
from lumpbeam_ros.core.model.statics import static_equilibrium

BASELINE_RTOL = 1e-6
BASELINE = f"solve_ivp(method='Radau', rtol={BASELINE_RTOL:g})"
RATE_HZ = 180.0


def _drop(duration_s: float) -> DropTestConfig:
    """A drop test released at once, so the whole record oscillates."""
    return DropTestConfig(release_time_s=0.0, duration_s=duration_s)


def _radau_drop_test(beam: BeamParameters, drop: DropTestConfig) -> np.ndarray:
    """The same drop test by the reference integrator; returns tip z at 180 Hz."""
    loaded = LumpedChain.from_beam(beam, drop.load_kg)
    released = LumpedChain.from_beam(beam, 0.0)
    state = ChainState(static_equilibrium(loaded), np.zeros(beam.n_segments))
    t = np.arange(int(round(drop.duration_s * RATE_HZ)) + 1) / RATE_HZ
    solution = solve_reference(released, state, t, rtol=BASELINE_RTOL, atol=BASELINE_RTOL * 1e-2)
    return released.tip_pose(solution.phi)[1]


def drop_test_speed(duration_s: float, repeat: int) -> BenchResult:
    """The drop test (n_s = 10) by the project's simulator and by Radau, timed and compared."""
    beam = BeamParameters(n_segments=10)
    drop = _drop(duration_s)
    ours, trajectory = best_time(lambda: simulate_drop_test(beam, drop, RATE_HZ), repeat)
    theirs, radau_z = best_time(lambda: _radau_drop_test(beam, drop), 1)
    return BenchResult(
        name='simulate_drop_test_ns10',
        value=ours,
        unit='s',
        baseline=BASELINE,
        baseline_value=theirs,
        ratio=theirs / ours,
        details={
            'simulated_s': duration_s,
            'samples': len(trajectory),
            'max_tip_difference_um': float(np.abs(trajectory.z - radau_z).max() * 1e6),
        },
    )


def scaling(segments: int, duration_s: float) -> BenchResult:
    """Wall time of a drop test with ``segments`` segments, against real time."""
    beam = replace(BeamParameters(), n_segments=segments)
    wall, _ = best_time(lambda: simulate_drop_test(beam, _drop(duration_s), RATE_HZ), 1)
    return BenchResult(
        name=f'simulate_drop_test_ns{segments}_cost',
        value=wall,
        unit='s',
        baseline='real time',
        baseline_value=duration_s,
        ratio=duration_s / wall,
        details={'ms_per_simulated_s': wall / duration_s * 1e3},
    )


def run(quick: bool = False) -> list[BenchResult]:
    """Runs the model suite.

    Args:
        quick: 1 s records and small chains only.

    Returns:
        The drop test against Radau, then the cost for growing n_s.
    """
    if quick:
        return [drop_test_speed(1.0, repeat=1), scaling(30, 1.0)]
    results = [drop_test_speed(10.0, repeat=5)]
    results += [scaling(n, 10.0) for n in (10, 30, 100, 300)]
    return results
