"""A camera and a laser tracker over one synthetic drop test, in memory."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lumpbeam_ros.core.bagio.tipseries import LoadSeries
from lumpbeam_ros.core.compare.streams import Track, clean_track
from lumpbeam_ros.core.model.parameters import BeamParameters, DropTestConfig
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, simulate_experiment, with_effects
from lumpbeam_ros.core.synthetic.reference_sensor import (
    ReferenceSamples,
    ReferenceSensorOptions,
    simulate_reference_sensor,
)

CAMERA_NOISE = 20e-6
TRACKER_NOISE = 15e-6
DURATION = 6.0


@dataclass(frozen=True)
class Pair:
    camera: Track
    reference: Track
    loads: LoadSeries
    tracker: ReferenceSensorOptions
    samples: ReferenceSamples


def make_pair(
    tracker: ReferenceSensorOptions | None = None,
    effects: dict[str, float] | None = None,
    camera_noise: float = CAMERA_NOISE,
    duration: float = DURATION,
    seed: int = 0,
) -> Pair:
    """Simulates both sensors; the camera stamps are true time (plus any latency effect)."""
    tracker = tracker or ReferenceSensorOptions(seed=seed + 1)
    beam, drop = BeamParameters(), DropTestConfig()
    options = SynthOptions(duration_s=duration, noise_m=camera_noise, effects=effects or {})
    measured, _ = simulate_experiment(beam, drop, options)
    rng = np.random.default_rng(seed)
    noise = camera_noise * rng.standard_normal((len(measured), 2))
    points = np.column_stack(
        [measured.x + noise[:, 0], np.zeros(len(measured)), measured.z + noise[:, 1]]
    )
    camera = clean_track(measured.t, points, 'beam_base', '/tip_pose', measured.pitch)
    samples = simulate_reference_sensor(
        with_effects(beam, options.effects), drop, duration, tracker
    )
    reference = clean_track(samples.stamps, samples.points, tracker.frame_id, '/tracker/point')
    loads = LoadSeries(np.array([0.0, drop.release_time_s]), np.array([drop.load_kg, 0.0]))
    return Pair(camera, reference, loads, tracker, samples)


def with_reference(pair: Pair, keep: np.ndarray, points: np.ndarray | None = None) -> Track:
    """The pair's reference with only the samples ``keep`` (and other positions, if given)."""
    ref = pair.reference
    new_points = ref.points[keep] if points is None else points
    return clean_track(ref.t[keep], new_points, ref.frame_id, ref.source)
