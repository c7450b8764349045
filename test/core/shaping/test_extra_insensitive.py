"""The EI shaper against the constraints that define it, and its closed form undamped."""

import numpy as np
import pytest

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.shaping.extra_insensitive import EI_MAX_DAMPING, ei_shaper
from lumpbeam_ros.core.shaping.impulses import Mode
from lumpbeam_ros.core.shaping.shapers import zvd_shaper
from lumpbeam_ros.core.shaping.vibration import insensitivity_band, residual_vibration


@pytest.mark.parametrize('tolerance', [0.05, 0.1])
def test_closed_form_without_damping(tolerance):
    impulses = ei_shaper(Mode(2.0, 0.0), tolerance)
    v = tolerance
    assert impulses.time_s.tolist() == pytest.approx([0.0, 0.25, 0.5], abs=1e-12)
    assert impulses.amplitude.tolist() == pytest.approx(
        [(1 + v) / 4, (1 - v) / 2, (1 + v) / 4], abs=1e-12
    )


@pytest.mark.parametrize('zeta', [0.0, 0.01, 0.05, 0.1, 0.2, 0.35, EI_MAX_DAMPING])
def test_damped_ei_meets_its_constraints(zeta):
    f = 4.0
    mode = Mode(f, zeta)
    impulses = ei_shaper(mode)
    assert np.sum(impulses.amplitude) == pytest.approx(1.0, abs=1e-15)
    assert np.all(impulses.amplitude > 0) and np.all(np.diff(impulses.time_s) > 0)
    # 5 % at the design frequency, and a local maximum there (a hump between two zeros).
    h = 1e-5 * f
    v_low, v_mid, v_high = residual_vibration(impulses, [f - h, f, f + h], zeta)
    assert v_mid == pytest.approx(0.05, abs=1e-10)
    assert (v_high - v_low) / (2 * h) == pytest.approx(0.0, abs=1e-6)
    assert v_low < v_mid and v_high < v_mid
    scan = np.linspace(0.6 * f, 2.0 * f, 28001)
    v = residual_vibration(impulses, scan, zeta)
    below, above = v[scan < f], v[scan > f]
    assert below.min() < 1e-3 and above.min() < 1e-3
    # Within the band around the design frequency the vibration never exceeds 5 %.
    low, high = insensitivity_band(impulses, mode, 0.05)
    inside = (scan > low) & (scan < high)
    assert v[inside].max() <= 0.05 + 1e-9
    assert high - low > insensitivity_band(zvd_shaper(mode), mode, 0.05)[1] - f


@pytest.mark.parametrize(
    ('zeta', 'tolerance', 'problem'),
    [
        (0.6, 0.05, 'EI shaper: damping ratio 0.6 is above 0.5 (use the ZVD shaper'),
        (0.0, 0.0, 'EI shaper: vibration tolerance must be in (0, 0.5), got 0.0'),
        (0.0, 0.5, 'EI shaper: vibration tolerance must be in (0, 0.5), got 0.5'),
    ],
)
def test_out_of_range_is_one_line(zeta, tolerance, problem):
    with pytest.raises(LumpbeamError) as caught:
        ei_shaper(Mode(1.0, zeta), tolerance)
    assert str(caught.value).startswith(problem)
