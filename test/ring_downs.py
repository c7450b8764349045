"""A rotary arm's move and ring-down written from known modes, for the identifier's tests.

The joint turns by a minimum-jerk move; once it stops, the tip vibrates across the link as a
sum of known damped modes (no simulator: the truth is what is written), with white noise on
x and z. Cheap enough for any test.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lumpbeam_ros.core.bagio import BagWriter

LENGTH_M = 0.419
MOVE_S = 0.3
RATE_HZ = 180.0
#: (natural frequency Hz, damping ratio, amplitude m) of the modes written.
MODES = ((4.2, 0.02, 5e-3), (26.0, 0.02, 4e-4))


@dataclass(frozen=True)
class ArmRecord:
    """Stamps, joint angles (n, 1), tip x and z."""

    t: np.ndarray
    q: np.ndarray
    x: np.ndarray
    z: np.ndarray


def ring_down(duration_s: float = 6.0, end_rad: float = 0.5, seed: int = 0) -> ArmRecord:
    """The move from 0 to ``end_rad`` in 0.3 s, then the modes ringing down."""
    t = np.arange(int(duration_s * RATE_HZ) + 1) / RATE_HZ
    s = np.clip(t / MOVE_S, 0.0, 1.0)
    q = end_rad * (10 * s**3 - 15 * s**4 + 6 * s**5)
    tau = np.maximum(t - MOVE_S, 0.0)
    swing = np.zeros_like(t)
    for f, zeta, amplitude in MODES:
        omega = 2 * math.pi * f
        omega_d = omega * math.sqrt(1 - zeta**2)
        swing += amplitude * np.exp(-zeta * omega * tau) * np.cos(omega_d * tau)
    swing[t < MOVE_S] = 0.0
    rng = np.random.default_rng(seed)
    # A positive angle turns the link from +x toward -z; the swing is across it.
    x = LENGTH_M * np.cos(q) + swing * np.sin(q) + rng.normal(0, 20e-6, t.size)
    z = -LENGTH_M * np.sin(q) + swing * np.cos(q) + rng.normal(0, 20e-6, t.size)
    return ArmRecord(t, q[:, None], x, z)


def write_bag(path: Path, record: ArmRecord, names: tuple[str, ...] = ('joint_1',)) -> Path:
    """Writes the record as an arm's bag: ``/joint_states`` and ``/tip_pose``."""
    with BagWriter(path) as bag:
        for i, stamp in enumerate(record.t):
            bag.write_joint_state('/joint_states', stamp, names, record.q[i])
            bag.write_pose('/tip_pose', stamp, record.x[i], record.z[i], 0.0)
    return path
