from dataclasses import replace

import numpy as np
import pytest

from lumpbeam_ros.core.model.chain import LumpedChain
from lumpbeam_ros.core.model.modes import chain_modes
from lumpbeam_ros.core.model.parameters import BeamParameters, DropTestConfig, Effects
from lumpbeam_ros.core.model.simulate import (
    BeamSimulation,
    SimulationDivergedError,
    simulate_drop_test,
    simulate_loads,
)
from lumpbeam_ros.core.model.statics import static_equilibrium, static_tip_deflection

BEAM = BeamParameters()


@pytest.fixture(scope='module')
def drop_test():
    return simulate_drop_test(BEAM)


def test_drop_test_starts_loaded_and_oscillates_about_the_released_level(drop_test):
    loaded = -static_tip_deflection(BEAM, 4.5)
    released = -static_tip_deflection(BEAM, 0.0)
    before = drop_test.between(0.0, 2.0)
    assert np.allclose(before.z, loaded, atol=1e-12)
    assert np.all(before.load_kg == 4.5)
    after = drop_test.between(2.0 + 1e-9, 12.1)
    assert np.all(after.load_kg == 0.0)
    assert after.z.max() > released > after.z.min()
    # The first swing reaches the level it fell from, minus the damping of half a period.
    assert after.z.min() == pytest.approx(loaded, rel=0.02)


def test_drop_test_oscillates_at_the_first_mode(drop_test):
    after = drop_test.between(2.0, 12.0)
    z = after.z - after.z.mean()
    crossings = after.t[1:][np.diff(np.sign(z)) > 0]
    period = np.diff(crossings).mean()
    mode = chain_modes(LumpedChain.from_beam(BEAM)).damped_frequency_hz[0]
    assert 1.0 / period == pytest.approx(mode, rel=2e-3)


def test_streaming_matches_batch(drop_test):
    simulation = BeamSimulation(BEAM, load_kg=4.5)
    t = drop_test.t
    chunks = [t[t < 2.0]]
    simulation_phi = [simulation.advance(chunks[0])[0]]
    simulation.advance(np.array([2.0]))
    simulation.set_load(0.0)
    rest = t[t >= 2.0]
    for part in np.array_split(rest, 17):
        simulation_phi.append(simulation.advance(part)[0])
    z = simulation.chain.tip_pose(np.vstack(simulation_phi))[1]
    assert np.max(np.abs(z - drop_test.z)) < 1e-8


def test_latency_delays_the_measurement():
    late = replace(BEAM, effects=Effects(latency_s=0.015))
    t = np.arange(0, 3.0, 1 / 1000)
    on_time = simulate_loads(BEAM, t, [(1.0, 0.0)], 4.5)
    delayed = simulate_loads(late, t, [(1.0, 0.0)], 4.5)
    shift = 15
    # The same motion, sampled on grids 15 ms apart: equal to within interpolation (~10 nm).
    assert np.max(np.abs(delayed.z[shift:] - on_time.z[:-shift])) < 1e-7
    assert np.max(np.abs(delayed.z - on_time.z)) > 1e-3


def test_event_at_the_start_releases_the_load():
    trajectory = simulate_drop_test(BEAM, DropTestConfig(release_time_s=0.0, duration_s=1.0))
    assert trajectory.z[0] == pytest.approx(-static_tip_deflection(BEAM, 4.5))
    assert np.ptp(trajectory.z) > 0.03


@pytest.mark.parametrize('load', [-1.0, float('nan'), float('inf')])
def test_bad_load_is_refused(load):
    with pytest.raises(ValueError, match='non-negative'):
        BeamSimulation(BEAM).set_load(load)


@pytest.mark.parametrize('times', [[], [1.0, 0.5], [-1.0]])
def test_bad_output_times_are_refused(times):
    simulation = BeamSimulation(BEAM, t0=0.0)
    with pytest.raises(ValueError, match='increasing'):
        simulation.advance(np.array(times))


def test_the_at_rest_start_is_the_loaded_equilibrium_exactly():
    beam = BeamParameters()
    t = np.linspace(0.0, 1.0, 181)
    trajectory = simulate_loads(beam, t, [(0.5, 0.0)], 4.5)
    chain = LumpedChain.from_beam(beam, 4.5)
    rest = static_equilibrium(chain)
    before = t < 0.5
    np.testing.assert_array_equal(trajectory.q[before], np.tile(rest, (before.sum(), 1)))
    assert np.ptp(trajectory.z[~before]) > 1e-3  # released: it swings


def test_a_beam_the_modal_solver_cannot_follow_is_refused_without_the_stiff_fallback():
    soft = replace(BeamParameters(), k_total_nm_per_rad=100.0)  # sags by tens of degrees
    with pytest.raises(SimulationDivergedError, match='extreme parameters'):
        simulate_loads(soft, np.linspace(0, 2, 361), [(0.5, 0.0)], 4.5, stiff_fallback=False)


def test_a_warm_start_reaches_the_same_trajectory_in_fewer_sweeps(monkeypatch):
    from lumpbeam_ros.core.model import integrate
    from lumpbeam_ros.core.model.simulate import WarmStart

    sweeps: list[int] = []
    propagate = integrate.ModalSolver._propagate

    def counted(self, *args):
        sweeps[-1] += 1
        return propagate(self, *args)

    monkeypatch.setattr(integrate.ModalSolver, '_propagate', counted)
    t = np.arange(0.0, 5.0, 1.0 / 180.0)
    nearby = replace(BEAM, k_total_nm_per_rad=BEAM.k_total_nm_per_rad * 1.002)

    def run(beam, warm=None):
        sweeps.append(0)
        return simulate_loads(beam, t, [(2.0, 0.0)], 4.5, warm=warm)

    cold = run(nearby)
    warm = WarmStart()
    assert not warm  # empty: nothing to start from
    run(BEAM, warm)  # a fit's previous step
    assert warm.get(2.0, 0.0) is not None and warm.get(2.0, 4.5) is None
    assert len(warm) == 1  # the one stretch that moves
    warmed = run(nearby, warm)
    # The same fixed point to the solver's tolerance (1e-11 rad between sweeps).
    assert np.max(np.abs(warmed.q - cold.q)) < 1e-9
    assert sweeps[2] < sweeps[0]
    # A remainder of another grid is not used: that run sweeps as a cold one does.
    shorter = t[t < 4.0]
    sweeps.append(0)
    simulate_loads(nearby, shorter, [(2.0, 0.0)], 4.5, warm=warm.copy())
    sweeps.append(0)
    simulate_loads(nearby, shorter, [(2.0, 0.0)], 4.5)
    assert sweeps[-2] == sweeps[-1]


@pytest.mark.parametrize('effect', [{}, {'coulomb_friction': 1.0}, {'quadratic_drag': 0.5}])
def test_a_fits_warm_simulations_stay_within_the_solvers_tolerance(effect, monkeypatch):
    from lumpbeam_ros.core.model import integrate
    from lumpbeam_ros.core.model.simulate import WarmStart

    effects = Effects()
    for name, value in effect.items():
        effects = effects.with_effect(name, value)
    t = np.arange(0.0, 6.0, 1.0 / 180.0)
    warm = WarmStart()
    # A fit's steps: each run starts from the previous one's remainder and contraction, and
    # may stop at its second sweep on the change predicted from them.
    steps = [(1.0, 1.0), (1.002, 1.0), (1.0, 1.003), (0.997, 1.002), (1.004, 0.998)]
    runs = []
    for k, b in steps:
        beam = replace(
            BEAM,
            effects=effects,
            k_total_nm_per_rad=BEAM.k_total_nm_per_rad * k,
            beta_identified=BEAM.beta_identified * b,
        )
        runs.append((beam, simulate_loads(beam, t, [(2.0, 0.0)], 4.5, warm=warm)))
    assert np.isfinite(warm.contraction(2.0, 0.0))
    solve = integrate.ModalSolver.solve
    monkeypatch.setattr(
        integrate.ModalSolver, 'solve', lambda self, *a, **k: solve(self, *a, **k, tol=1e-15)
    )
    for beam, run in runs:
        strict = simulate_loads(beam, t, [(2.0, 0.0)], 4.5)
        assert np.max(np.abs(run.q - strict.q)) < 1e-11  # the solver's tolerance, rad
