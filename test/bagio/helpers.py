"""Bags for the bagio tests: a stand-in drop test (damped sinusoid, not the beam model)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from lumpbeam_ros.bagio import BagWriter

T0 = 1_700_000_000.0  # an epoch offset, as a real recording has


def stand_in_drop(rate_hz: float = 180.0, duration: float = 4.0) -> dict[str, np.ndarray]:
    """Tip samples: -0.05 m sag until t = 2 s, then a 3.1 Hz damped oscillation about -0.01 m."""
    t = np.arange(0.0, duration, 1.0 / rate_hz)
    after = np.clip(t - 2.0, 0.0, None)
    z = np.where(
        t < 2.0,
        -0.05,
        -0.01 - 0.04 * np.exp(-0.03 * 2 * np.pi * 3.1 * after) * np.cos(2 * np.pi * 3.1 * after),
    )
    return {'t': t, 'x': 2.31 - 0.1 * z**2, 'z': z, 'pitch': -1.5 * z / 2.31}


def write_drop_bag(path: Path, images: int = 0, flush_every: int = 36) -> dict:
    """Writes poses, the load and optionally small mono8 images; returns the samples.

    A flush every ``flush_every`` samples (0.2 s) cuts the file into 20 chunks, as a live
    recording's periodic flushes do.
    """
    s = stand_in_drop()
    with BagWriter(path) as bag:
        for i, t in enumerate(s['t']):
            bag.write_pose('/tip_pose', T0 + t, s['x'][i], s['z'][i], s['pitch'][i])
            if i % 18 == 0:
                bag.write_float('/tip_load', T0 + t, 4.5 if t < 2.0 else 0.0)
            if i < images:
                bag.write_image('/camera/image_raw', T0 + t, np.full((8, 10), i, np.uint8))
            if i % flush_every == flush_every - 1:
                bag.flush()
    return s
