import math

import numpy as np
import pytest

from lumpbeam_lab.ident.ssi_cov import ssi_cov_modes

RATE = 180.0
T = np.arange(0.0, 10.0, 1.0 / RATE)


def decay(f: float, zeta: float, amplitude: float, phase: float) -> np.ndarray:
    w = 2.0 * math.pi * f
    return amplitude * np.exp(-zeta * w * T) * np.cos(w * math.sqrt(1.0 - zeta**2) * T + phase)


def test_a_clean_free_decay_gives_its_own_pole_exactly():
    # An offset and one damped mode: the fixed-length correlations hold only its poles (and
    # spare ones far out of band from the order left over).
    modes = ssi_cov_modes(0.5 + decay(3.0, 0.002, 0.04, 0.3), RATE, order=4, block_rows=60)
    in_band = [m for m in modes if m[0] < 20.0]
    assert len(in_band) == 1
    assert in_band[0][0] == pytest.approx(3.0, rel=1e-9)
    assert in_band[0][1] == pytest.approx(0.002, rel=1e-6)


def test_two_modes_are_told_apart():
    y = decay(3.0, 0.002, 0.04, 0.3) + decay(11.0, 0.01, 0.01, 1.0)
    modes = [m for m in ssi_cov_modes(y, RATE, order=6, block_rows=60) if m[0] < 20.0]
    assert [f for f, _ in modes] == pytest.approx([3.0, 11.0], rel=1e-4)
    assert [zeta for _, zeta in modes] == pytest.approx([0.002, 0.01], rel=1e-2)


def test_too_short_a_signal_or_too_high_an_order_is_refused():
    with pytest.raises(ValueError, match='samples'):
        ssi_cov_modes(np.zeros(100), RATE, block_rows=60)
    with pytest.raises(ValueError, match='order'):
        ssi_cov_modes(np.zeros(1000), RATE, order=80, block_rows=60)
