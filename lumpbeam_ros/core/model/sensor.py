"""The sensor's own effect on a measured tip position: ``sensor_scale``.

(``sensor_latency`` is a time shift, applied where the samples are simulated:
:func:`~lumpbeam_ros.core.model.simulate.simulate_loads`,
:class:`~lumpbeam_ros.core.model.stream.PredictionStream`.)

A camera that takes the board for nearer or farther than it is scales every lateral
displacement it measures by the same factor and leaves the angles alone: the measured tip
position's displacement from rest is ``scale`` times the true one, the pitch is true. Rest is
the beam's static equilibrium without a hanging load (its mounted body only), the pose a
rig is set up and zeroed at.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from lumpbeam_ros.core.model.chain import LumpedChain
from lumpbeam_ros.core.model.parameters import BeamParameters
from lumpbeam_ros.core.model.statics import static_equilibrium


@lru_cache(maxsize=64)
def rest_position(beam: BeamParameters) -> tuple[float, float]:
    """``(x, z)`` of the free end at rest without a hanging load, m (cached per beam)."""
    chain = LumpedChain.from_beam(beam, 0.0)
    x, z, _ = chain.tip_pose(static_equilibrium(chain))
    return float(x), float(z)


def scaled_position(
    beam: BeamParameters, x: np.ndarray, z: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The tip position as a sensor with ``beam.effects``' scale measures it.

    Args:
        beam: The beam (its ``sensor_scale`` effect is applied; 1 returns the input).
        x: True x of the free end, m.
        z: True z, same shape.

    Returns:
        ``rest + scale (true - rest)`` for x and z.
    """
    scale = beam.effects.scale
    if scale == 1.0:
        return x, z
    x0, z0 = rest_position(beam)
    return x0 + scale * (np.asarray(x) - x0), z0 + scale * (np.asarray(z) - z0)


def measured_position(
    beam: BeamParameters, elapsed_s: np.ndarray, x: np.ndarray, z: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The tip position as the sensor reports it: scaled, and moved by a creeping mount.

    A clamp creeping at a constant rate (``mount_creep``) moves the beam with it at a
    constant velocity, which loads it with no inertial force: its motion relative to the
    clamp is unchanged, and only the measured z (taken against the fixed board) moves by
    ``rate * elapsed``.

    Args:
        beam: The beam (its ``sensor_scale`` and ``mount_creep`` effects are applied).
        elapsed_s: Time of each sample since the record (or the stream) began, s.
        x: True x of the free end, m.
        z: True z, same shape.

    Returns:
        The measured x and z.
    """
    x, z = scaled_position(beam, x, z)
    rate = beam.effects.creep_rate_mps
    if rate == 0.0:
        return x, z
    return x, np.asarray(z) + rate * np.asarray(elapsed_s)
