import math
from dataclasses import replace

import numpy as np
import pytest

from lumpbeam_ros.core.model.parameters import BeamParameters
from lumpbeam_ros.core.model.simulate import (
    BeamSimulation,
    SimulationDivergedError,
    simulate_loads,
)
from lumpbeam_ros.core.model.stream import REWIND_S, PredictionStream

BEAM = BeamParameters()


def _run(stream, until, seed=0, start=None):
    """Advances with irregular ticks (1 to 50 ms) and concatenates what came out."""
    rng = np.random.default_rng(seed)
    now = stream.time if start is None else start
    parts = []
    while now < until:
        now = min(until, now + rng.uniform(0.001, 0.05))
        parts.append(stream.advance_to(now))
    t = np.concatenate([p.t for p in parts])
    z = np.concatenate([p.z for p in parts])
    pitch = np.concatenate([p.pitch for p in parts])
    return t, z, pitch


@pytest.mark.parametrize(
    'effects',
    [
        {},
        {'sensor_latency': 0.013},
        {'sensor_scale': 1.05, 'mount_tilt': 0.1, 'cubic_stiffness': 5e7},
        {'mount_creep': 3e-4},  # counted from the stream's start, as from the record's
    ],
)
@pytest.mark.parametrize('t0', [0.0, 1_700_000_000.25])
def test_matches_the_batch_simulation_on_the_same_stamps(effects, t0):
    beam = replace(BEAM, effects=BEAM.effects)
    for name, value in effects.items():
        beam = replace(beam, effects=beam.effects.with_effect(name, value))
    stream = PredictionStream(beam, 4.5, t0, rate_hz=180.0)
    stream.set_load(t0 + 1.0, 0.0)
    stream.set_load(t0 + 2.5, 1.0)
    t, z, pitch = _run(stream, t0 + 4.0)
    assert np.all(np.diff(t) > 0)
    np.testing.assert_allclose(np.diff(t), 1 / 180, atol=1e-6)
    assert t[0] == pytest.approx(t0, abs=1e-9) and t[-1] == pytest.approx(t0 + 4.0, abs=1e-6)
    # The batch run starts at rest at t0 - latency, as the stream does.
    ref = simulate_loads(beam, t - t0, [(1.0, 0.0), (2.5, 1.0)], 4.5)
    # Chunked runs interpolate on other internal grids (below 1 um, a twentieth of the camera
    # noise); epoch stamps also carry ~0.2 us of float rounding.
    tol = 1e-6 if t0 == 0.0 else 2e-5
    np.testing.assert_allclose(z, ref.z, atol=tol)
    # Right after a load change the pitch carries the 35 Hz second mode, which cubic
    # interpolation on a 1/180 s grid renders to ~1e-5 rad: a fifth of the camera's 0.05 mrad.
    np.testing.assert_allclose(pitch, ref.pitch, atol=max(tol, 2e-5))


def test_starts_at_the_loaded_equilibrium_and_settles_after_the_drop():
    stream = PredictionStream(BEAM, 4.5, 0.0)
    assert stream.equilibrium_pose()[1] == pytest.approx(-0.0694, abs=5e-4)
    stream.set_load(0.5, 0.0)
    t, z, _ = _run(stream, 4.0)
    assert np.ptp(z[t < 0.5]) < 1e-12
    after = z[t > 1.0]
    assert np.mean(after) == pytest.approx(-0.0286, abs=1e-3)
    crossings = np.flatnonzero(np.diff(np.sign(after - np.mean(after))) > 0)
    period = np.mean(np.diff(t[t > 1.0][crossings]))
    assert 1 / period == pytest.approx(3.06, abs=0.03)


def _ticks(stream, start, until, period=0.01):
    """Advances at a steady period; the samples' stamps and heights."""
    parts = [
        stream.advance_to(k * period)
        for k in range(round(start / period) + 1, round(until / period) + 1)
    ]
    return np.concatenate([p.t for p in parts]), np.concatenate([p.z for p in parts])


@pytest.mark.parametrize(
    ('late_s', 'released_s', 'early_ticks'),
    [
        (0.03, 0.97, 0),  # a message a few ticks late: simulated again from its own instant
        (0.8, 0.2, 0),
        # Older than the rewind reaches: from its oldest checkpoint, on the stamp grid.
        (REWIND_S + 0.5, 1.5 - REWIND_S, 2),
    ],
)
def test_a_late_load_change_is_simulated_again_from_its_instant(late_s, released_s, early_ticks):
    now = round(released_s + late_s, 2) if late_s < REWIND_S else 1.5
    stream = PredictionStream(BEAM, 4.5, 0.0)
    t1, z1 = _ticks(stream, 0.0, now)
    stream.set_load(now - late_s, 0.0)
    t2, z2 = _ticks(stream, now, now + 0.5)
    assert np.ptp(z1) < 1e-12  # what was returned before the message stays as it was
    gaps = [
        np.max(np.abs(z2 - simulate_loads(BEAM, t2, [(released, 0.0)], 4.5).z))
        for released in released_s - np.arange(early_ticks + 1) / 180
    ]
    assert min(gaps) < 1e-6 and np.ptp(z2) > 0.01


def test_a_late_load_change_after_a_new_beam_applies_at_the_present():
    stream = PredictionStream(BEAM, 4.5, 0.0)
    t1, _ = _ticks(stream, 0.0, 1.0)
    stream.set_beam(BEAM)  # the past would be simulated with the new beam: not again
    stream.set_load(0.2, 0.0)
    t2, z2 = _ticks(stream, 1.0, 1.5)
    ref = simulate_loads(BEAM, np.concatenate([t1, t2]), [(1.0, 0.0)], 4.5)
    np.testing.assert_allclose(z2, ref.z[t1.size :], atol=1e-6)


def test_reset_restarts_at_rest_without_repeating_stamps():
    stream = PredictionStream(BEAM, 4.5, 0.0)
    stream.set_load(0.1, 0.0)
    first, _, _ = _run(stream, 0.5)
    stream.reset(0.5)  # a first /tip_load: same time, nothing published twice
    t, z, _ = _run(stream, 0.6)
    assert t[0] > first[-1]
    assert np.ptp(z) < 1e-12 and stream.load_kg == 0.0
    stream.reset(0.0, 4.5)  # the clock went back: the grid starts again
    t, z, _ = _run(stream, 0.1)
    assert t[0] == 0.0 and z[0] == pytest.approx(stream.equilibrium_pose()[1])


def test_a_failed_simulation_restarts_at_rest_instead_of_falling_behind(monkeypatch):
    stream = PredictionStream(BEAM, 4.5, 0.0)
    stream.set_load(0.1, 0.0)
    _run(stream, 1.0)  # ringing
    advance = BeamSimulation.advance

    def diverge(simulation, t_out):
        raise SimulationDivergedError('the modal solver did not converge')

    monkeypatch.setattr(BeamSimulation, 'advance', diverge)
    with pytest.raises(SimulationDivergedError):
        stream.advance_to(2.0)
    spans = []

    def record(simulation, t_out):
        spans.append((simulation.time, float(t_out[-1])))
        return advance(simulation, t_out)

    monkeypatch.setattr(BeamSimulation, 'advance', record)
    t, z, _ = _run(stream, 2.5, start=2.0)
    # At rest from the failure on under the load of the moment: nothing simulated twice.
    assert t[0] > 2.0 and min(start for start, _ in spans) >= 2.0 - 1e-9
    assert np.ptp(z) < 1e-12 and z[0] == pytest.approx(stream.equilibrium_pose()[1])


def test_set_beam_keeps_the_motion():
    def run(swap_to):
        stream = PredictionStream(BEAM, 4.5, 0.0)
        stream.set_load(0.0, 0.0)
        _run(stream, 1.0)
        if swap_to is not None:
            stream.set_beam(swap_to)
        return stream, _run(stream, 3.0, seed=1)[1]

    _, z_plain = run(None)
    _, z_same = run(BEAM)  # swapping in the same beam changes nothing
    np.testing.assert_allclose(z_same, z_plain, atol=1e-7)
    stiffer = replace(BEAM, k_total_nm_per_rad=2 * BEAM.k_total_nm_per_rad)
    stream, z_stiff = run(stiffer)
    assert abs(z_stiff[0] - z_plain[0]) < 1e-3  # continuous (a step moves the tip ~4 mm)

    # ...and then about the stiffer beam's static level, which is higher.
    def centre(z):
        return 0.5 * (z[-180:].max() + z[-180:].min())

    assert centre(z_stiff) == pytest.approx(stream.equilibrium_pose()[1], abs=1e-3)
    assert centre(z_stiff) > centre(z_plain) + 0.01
    with pytest.raises(ValueError, match='segments'):
        stream.set_beam(replace(BEAM, n_segments=4))


def test_rate_change_keeps_the_stamps_increasing():
    stream = PredictionStream(BEAM, 0.0, 0.0, rate_hz=180.0)
    t1, _, _ = _run(stream, 0.5)
    stream.rate_hz = 50.0
    t2, _, _ = _run(stream, 1.0)
    assert t2[0] > t1[-1]
    np.testing.assert_allclose(np.diff(t2), 0.02, atol=1e-9)


@pytest.mark.parametrize('bad', [-1.0, math.nan, math.inf])
def test_rejects_bad_loads_and_rates(bad):
    stream = PredictionStream(BEAM, 0.0, 0.0)
    with pytest.raises(ValueError, match='tip load'):
        stream.set_load(1.0, bad)
    with pytest.raises(ValueError, match='tip load'):
        PredictionStream(BEAM, bad, 0.0)
    with pytest.raises(ValueError, match='rate'):
        stream.rate_hz = bad
    with pytest.raises(ValueError, match='time'):
        stream.set_load(math.nan, 1.0)


def test_nothing_due_gives_empty_samples():
    stream = PredictionStream(BEAM, 0.0, 1.0)
    assert len(stream.advance_to(1.0)) == 0  # the clock has not moved
    assert len(stream.advance_to(0.5)) == 0  # went back: the caller decides
    assert len(stream.advance_to(1.001)) == 1  # the stamp at 1.0


@pytest.mark.parametrize('t0', [3 / 180 + 3e-10, 1.0 + 1e-10, 2.5 - 1e-10])
def test_start_a_hair_after_a_stamp_includes_it(t0):
    # A /clock in whole nanoseconds lands a fraction of a nanosecond off the 1/180 s grid.
    stream = PredictionStream(BEAM, 4.5, t0)
    samples = stream.advance_to(t0 + 0.1)
    assert samples.t[0] == pytest.approx(t0, abs=1e-9)
    assert np.ptp(samples.z) < 1e-12


@pytest.mark.parametrize('frames', [4, -4])
def test_a_new_latency_shows_the_motion_that_much_later(frames):
    # Four frames at 180 Hz: the changed stream's samples are the reference's, shifted.
    beam = BeamParameters()
    before = replace(beam, effects=beam.effects.with_effect('sensor_latency', 8 / 180))
    after = replace(beam, effects=beam.effects.with_effect('sensor_latency', (8 + frames) / 180))
    changed = PredictionStream(before, 4.5, 0.0, 180.0)
    reference = PredictionStream(after, 4.5, 0.0, 180.0)
    for stream in (changed, reference):
        stream.set_load(0.5, 0.0)
    changed.advance_to(1.0)
    reference.advance_to(1.0)
    changed.set_beam(after)
    shown = changed.advance_to(2.0)
    expected = reference.advance_to(2.0)
    # After the hold (longer latency) or the skip (shorter), the two show the same motion.
    settled = shown.t >= 1.0 + 2 * abs(frames) / 180
    np.testing.assert_allclose(shown.z[settled], expected.z[settled], atol=2e-6)
    assert np.all(np.diff(shown.t) > 0)
