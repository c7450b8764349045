"""Synthetic records of struck structures with known modes, for the free-vibration checks.

Each mode rings from the tap on as ``a e^{-sigma tau} sin(omega_d tau + phase)``, switched
on over a fraction of a millisecond as a hammer's contact would; lines, noise, quantization
and clipping are added as a lab's record has them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Tap:
    """A record to synthesize.

    Attributes:
        rate_hz: Sampling rate.
        duration_s: Length of the record.
        taps_s: When the structure is struck (each tap rings every mode afresh).
        modes: ``(natural frequency Hz, damping ratio, amplitude)`` per mode.
        noise: White noise's standard deviation.
        hum: ``(frequency Hz, amplitude)`` of a steady line, or ``None``.
        step: Quantization step (0: none).
        clip: The sensor's range: samples beyond it read as its limit (0: none).
    """

    rate_hz: float
    duration_s: float
    taps_s: tuple[float, ...]
    modes: tuple[tuple[float, float, float], ...]
    noise: float = 0.0
    hum: tuple[float, float] | None = None
    step: float = 0.0
    clip: float = 0.0

    def record(self, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
        """The stamps and samples."""
        rng = np.random.default_rng(seed)
        t = np.arange(int(self.rate_hz * self.duration_s)) / self.rate_hz
        y = np.zeros_like(t)
        for tap in self.taps_s:
            tau = np.maximum(t - tap, 0.0)
            for f, zeta, a in self.modes:
                wn = 2 * np.pi * f
                wd = wn * np.sqrt(1 - zeta * zeta)
                ring = a * np.exp(-zeta * wn * tau) * np.sin(wd * tau + rng.uniform(0, 2 * np.pi))
                y += np.where(t >= tap, ring * (1 - np.exp(-tau * 5000.0)), 0.0)
        if self.hum is not None:
            y += self.hum[1] * np.sin(2 * np.pi * self.hum[0] * t + rng.uniform(0, 2 * np.pi))
        y += self.noise * rng.standard_normal(t.size)
        if self.step:
            y = self.step * np.round(y / self.step)
        if self.clip:
            y = np.clip(y, -self.clip, self.clip)
        return t, y


#: A lab's records with their truth: a tapped steel cantilever with an accelerometer and
#: mains hum, a beam struck and filmed at 15 kHz, a structure at half a hertz, a 1.79 Hz ring
#: of 9 mm in 1 mm steps, a record clipped by its sensor.
RECORDS = {
    'tapped_cantilever': Tap(1650, 20, (1.0,), ((6.62, 0.004, 10.0), (41.4, 0.003, 5.0),
                             (117.5, 0.002, 3.0)), noise=0.05, hum=(50.0, 0.2)),
    'struck_beam_15khz': Tap(15000, 0.25, (0.02,), ((695.0, 0.01, 1.0), (1897.5, 0.01, 0.6)),
                             noise=0.02),
    'half_a_hertz': Tap(50, 120, (5.0,), ((0.5, 0.01, 1.0),), noise=0.01),
    'quantized_ring': Tap(1000, 6, (0.5,), ((1.79, 0.01, 9.0),), step=1.0),
    'clipped': Tap(2000, 4, (0.2,), ((12.0, 0.02, 1.0), (75.0, 0.01, 0.3)), noise=0.003,
                   clip=0.7),
}  # fmt: skip
