"""Synthetic drop tests for the identifier tests.

``drop_case`` is the one place that makes test data. Until the lead's
``lumpbeam_ros.model.simulate.simulate_drop_test`` is on main it is a stand-in: the free
response of a two-mode linear system from rest, with the static step of B.12. Swap its body
for the simulator (truth: the linearised model's first mode from ``model.modes`` and the
difference of the model's static equilibria) and every test below keeps working.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pytest

from lumpbeam_ros.model.parameters import BeamParameters, DropTestConfig
from lumpbeam_ros.model.trajectory import TipTrajectory


@dataclass(frozen=True)
class Truth:
    """What the identifier should find in a drop case."""

    natural_frequency_hz: float
    damping_ratio: float
    static_deflection_m: float
    stiffness_total_nm_per_rad: float
    release_time_s: float


DropCase = Callable[..., tuple[TipTrajectory, Truth]]

# Stand-in first mode: k_vertical = 3 k_tE / (2 L^2) (B.12) on m_d + (33/140) m_b gives
# 3.07 Hz; the identified joints have c / k = beta c_tE / k_tE (B.13, B.23), i.e.
# stiffness-proportional damping, zeta = (c / k) omega / 2.
_F1_HZ = 3.07
_F2_HZ = 25.0
_SECOND_MODE_SHARE = 0.01


def _free_decay(tau: np.ndarray, f_hz: float, zeta: float) -> np.ndarray:
    """Unit free response from rest of one mode: 1 at tau = 0, zero velocity."""
    wn = 2.0 * math.pi * f_hz
    sigma, wd = zeta * wn, wn * math.sqrt(1.0 - zeta * zeta)
    return np.exp(-sigma * tau) * (np.cos(wd * tau) + sigma / wd * np.sin(wd * tau))


def make_drop_case(
    beam: BeamParameters | None = None,
    drop: DropTestConfig | None = None,
    *,
    damping_scale: float = 1.0,
    noise_m: float = 20e-6,
    pitch_noise_rad: float = 1e-5,
    rate_hz: float = 180.0,
    seed: int = 0,
) -> tuple[TipTrajectory, Truth]:
    """A drop test: the tip at rest under the load, released, then a free decay.

    Args:
        beam: The beam (default: the identified beam of SPEC section 1, n_s = 10).
        drop: Load, release time and duration (default: 4.5 kg at 2 s, 12 s).
        damping_scale: Multiplies the damping ratio.
        noise_m: Std of the white noise on z.
        pitch_noise_rad: Std of the white noise on the pitch.
        rate_hz: Pose rate.
        seed: Noise seed.

    Returns:
        The trajectory (with the load at each sample) and the truth.
    """
    beam = beam or BeamParameters()
    drop = drop or DropTestConfig()
    t = np.arange(0.0, drop.duration_s, 1.0 / rate_hz)
    force = drop.load_kg * beam.gravity_mps2
    k_vertical = 3.0 * beam.k_total_nm_per_rad / (2.0 * beam.length_m**2)
    step = force / k_vertical
    c_over_k = beam.beta_identified * beam.c_total / beam.k_total_nm_per_rad
    zeta1 = damping_scale * 0.5 * c_over_k * 2.0 * math.pi * _F1_HZ
    zeta2 = damping_scale * 0.5 * c_over_k * 2.0 * math.pi * _F2_HZ
    before = -0.05
    tau = np.maximum(t - drop.release_time_s, 0.0)
    shape = (1.0 - _SECOND_MODE_SHARE) * _free_decay(tau, _F1_HZ, zeta1)
    shape += _SECOND_MODE_SHARE * _free_decay(tau, _F2_HZ, zeta2)
    exact = before + step * (1.0 - shape)
    rng = np.random.default_rng(seed)
    z = exact + rng.normal(0.0, noise_m, t.size)
    # Tip slope of an end-loaded cantilever, F L^2 / (2 EI) = 1.5 deflection / L (B.3, B.4).
    pitch = -1.5 * exact / beam.length_m + rng.normal(0.0, pitch_noise_rad, t.size)
    load = np.where(t < drop.release_time_s, drop.load_kg, 0.0)
    trajectory = TipTrajectory(t, np.full(t.size, beam.length_m), z, pitch, load)
    truth = Truth(_F1_HZ, zeta1, step, beam.k_total_nm_per_rad, drop.release_time_s)
    return trajectory, truth


@pytest.fixture
def drop_case() -> DropCase:
    """The drop-test generator (see :func:`make_drop_case`)."""
    return make_drop_case
