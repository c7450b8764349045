"""A synthetic laser tracker beside the camera (``lumpbeam synth --tracker``).

Like the paper's Leica AT960 (Fig. B.8), it follows a retroreflector at the tip: the true
motion of the beam (every physical effect, but no camera latency), sampled fast on its own
clock, with its own noise, in its own frame, published as ``/tracker/point``
(``geometry_msgs/msg/PointStamped``, doc/interfaces.md, 'Topics').
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import TRACKER_POINT
from lumpbeam_ros.core.bagio import BagWriter
from lumpbeam_ros.core.compare.transforms import RigidTransform
from lumpbeam_ros.core.model.parameters import BeamParameters, DropTestConfig
from lumpbeam_ros.core.model.simulate import drop_test_events, simulate_loads

TOPIC = TRACKER_POINT


@dataclass(frozen=True)
class ReferenceSensorOptions:
    """The synthetic tracker.

    Attributes:
        rate_hz: Sample rate, Hz.
        noise_m: Standard deviation of the noise on each coordinate, m.
        clock_offset_s: Tracker clock minus true time: a sample of the instant ``t`` is
            stamped ``t + clock_offset_s``.
        position_m: The tracker frame's origin in ``beam_base``, m (default: 3 m beside the
            beam, level with the clamp, opposite its middle).
        rotation_deg: The tracker frame's orientation in ``beam_base`` as extrinsic x-y-z
            (roll, pitch, yaw) angles, degrees.
        lever_m: Distance of the retroreflector from the tip along the beam's end tangent, m
            (positive beyond the tip).
        frame_id: ``header.frame_id`` of the points.
        seed: Seed of the noise.
    """

    rate_hz: float = 1000.0
    noise_m: float = 15e-6
    clock_offset_s: float = 7.3e-3
    position_m: tuple[float, float, float] = (1.2, -3.0, 0.35)
    rotation_deg: tuple[float, float, float] = (4.0, -8.0, 100.0)
    lever_m: float = 0.0
    frame_id: str = 'tracker'
    seed: int = 1

    def __post_init__(self) -> None:
        finite = [self.rate_hz, self.noise_m, self.clock_offset_s, self.lever_m]
        finite += [*self.position_m, *self.rotation_deg]
        if not all(math.isfinite(v) for v in finite):
            raise LumpbeamError('tracker options must be finite numbers')
        if self.rate_hz <= 0.0 or self.noise_m < 0.0:
            raise LumpbeamError(
                f'tracker rate must be positive and noise non-negative, got '
                f'{self.rate_hz} Hz and {self.noise_m} m'
            )
        if not self.frame_id:
            raise LumpbeamError('the tracker frame id must not be empty')

    @property
    def transform(self) -> RigidTransform:
        """Tracker frame to ``beam_base`` (the tracker's pose in ``beam_base``)."""
        return RigidTransform.from_euler_deg(self.rotation_deg, self.position_m)


@dataclass(frozen=True)
class ReferenceSamples:
    """What the tracker publishes.

    Attributes:
        stamps: Stamps on the tracker clock, s.
        points: Reflector positions in the tracker frame, ``(n, 3)``, m.
        true_points: The same without noise, in ``beam_base``, ``(n, 3)``, m.
        frame_id: The tracker frame.
    """

    stamps: np.ndarray
    points: np.ndarray
    true_points: np.ndarray
    frame_id: str

    def __len__(self) -> int:
        return int(self.stamps.size)


def simulate_reference_sensor(
    beam: BeamParameters, drop: DropTestConfig, duration_s: float, options: ReferenceSensorOptions
) -> ReferenceSamples:
    """Simulates the tracker over a drop test.

    Args:
        beam: The beam as it really is (hidden effects included; ``sensor_latency`` and
            ``sensor_scale`` are the camera's, so they are removed here).
        drop: The load and its release time.
        duration_s: Length of the record in true time, s.
        options: The tracker.

    Returns:
        The samples from true time 0 (or from the first with a non-negative stamp).
    """
    physical = replace(beam, effects=beam.effects.physical())
    count = int(math.floor(duration_s * options.rate_hz + 1e-9)) + 1
    t = np.arange(count) / options.rate_hz
    t = t[t + options.clock_offset_s >= 0.0]  # ROS time has no negative stamps
    tip = simulate_loads(physical, t, drop_test_events(drop), drop.load_kg)
    # The end tangent is the beam_base x axis rotated by the pitch about +y.
    x = tip.x + options.lever_m * np.cos(tip.pitch)
    z = tip.z - options.lever_m * np.sin(tip.pitch)
    true_points = np.column_stack([x, np.zeros_like(x), z])
    rng = np.random.default_rng(options.seed)
    in_tracker = options.transform.inverse().apply(true_points)
    noisy = in_tracker + options.noise_m * rng.standard_normal(in_tracker.shape)
    return ReferenceSamples(t + options.clock_offset_s, noisy, true_points, options.frame_id)


def write_reference_points(
    bag: BagWriter, samples: ReferenceSamples, start: int, until_s: float
) -> int:
    """Writes the samples from index ``start`` whose stamps are ``<= until_s``.

    Called between the camera's poses, it keeps the bag in time order.

    Args:
        bag: An open writer.
        samples: The tracker samples.
        start: First index not written yet.
        until_s: Latest stamp to write now, s.

    Returns:
        The next index not written.
    """
    end = int(np.searchsorted(samples.stamps, until_s, side='right'))
    for i in range(start, max(start, end)):
        x, y, z = samples.points[i]
        bag.write_point(TOPIC, float(samples.stamps[i]), x, y, z, samples.frame_id)
    return max(start, end)
