import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.pencil import MatrixPencil

T = np.arange(0.0, 6.0, 1.0 / 180.0)


def _mode(f_d, zeta, amp):
    w = 2 * math.pi * f_d
    return amp * np.exp(-zeta * w / math.sqrt(1 - zeta**2) * T) * np.cos(w * T + 0.4)


@pytest.mark.parametrize('decimation', [1, 2])
def test_two_modes_and_offset(decimation):
    rng = np.random.default_rng(0)
    y = -0.01 + _mode(3.1, 0.01, 0.03) + _mode(22.0, 0.02, 0.001)
    y += rng.normal(0, 5e-6, T.size)
    result = MatrixPencil(decimation=decimation).fit(T, y)
    first, second = result.modes[:2]
    assert first.damped_frequency_hz == pytest.approx(3.1, rel=1e-4)
    assert first.damping_ratio == pytest.approx(0.01, rel=0.02)
    assert second.damped_frequency_hz == pytest.approx(22.0, rel=1e-3)
    assert result.offset == pytest.approx(-0.01, abs=1e-5)
    assert result.sample_rate_hz == pytest.approx(180.0 / decimation)


def test_uneven_stamps_are_resampled():
    t = T + np.random.default_rng(1).uniform(-5e-4, 5e-4, T.size)
    result = MatrixPencil().fit(t, _mode(3.1, 0.01, 0.03))
    assert result.modes[0].damped_frequency_hz == pytest.approx(3.1, rel=1e-3)


def test_too_few_samples_and_bad_settings():
    with pytest.raises(LumpbeamError, match='too few'):
        MatrixPencil().fit(T[:15], T[:15])
    with pytest.raises(ValueError):
        MatrixPencil(order=10, pencil_length=5)


#: The fuzz campaign's identifier case 860 (a drop test's window after a small stamp jump):
#: one spurious pole grows by more than 1e308 over the 537 samples.
GROWING_POLE = Path(__file__).resolve().parents[2] / 'data' / 'pencil_growing_pole.npz'

FIT_GROWING_POLE = f"""
import numpy as np
from lumpbeam_ros.core.ident.pencil import MatrixPencil

record = np.load({str(GROWING_POLE)!r})
modes = MatrixPencil(7, 40, 1).fit(record['t'], record['y']).modes
print(min(modes, key=lambda m: abs(m.natural_frequency_hz - 3.06)).natural_frequency_hz)
"""


def test_a_pole_that_overflows_the_record_is_left_out():
    """LAPACK's least squares on the inf Vandermonde matrix never returned: a hung node."""
    done = subprocess.run(
        [sys.executable, '-c', FIT_GROWING_POLE], capture_output=True, text=True, timeout=60
    )
    assert done.returncode == 0, done.stderr
    assert float(done.stdout) == pytest.approx(3.06, abs=0.01)


def test_samples_near_the_float_limit_are_a_one_line_error():
    """Finite but 1e308: the centring overflowed and the SVD failed with a bare LinAlgError."""
    y = -0.01 + _mode(3.1, 0.01, 0.03)
    y[100:103] = 1e308
    with pytest.raises(LumpbeamError, match='too large'):
        MatrixPencil().fit(T, y)
