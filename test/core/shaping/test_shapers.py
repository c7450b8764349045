"""ZV and ZVD against their defining constraints, the shapers by name, several modes."""

import math

import numpy as np
import pytest

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.shaping.impulses import Mode
from lumpbeam_ros.core.shaping.shapers import SHAPERS, design_shaper, zv_shaper, zvd_shaper
from lumpbeam_ros.core.shaping.vibration import insensitivity_band, residual_vibration

DAMPINGS = [0.0, 0.005, 0.02, 0.1, 0.3, 0.7]


@pytest.mark.parametrize('zeta', DAMPINGS)
@pytest.mark.parametrize('shaper', [zv_shaper, zvd_shaper])
def test_no_vibration_at_the_design_frequency(shaper, zeta):
    mode = Mode(2.7, zeta)
    impulses = shaper(mode)
    assert np.sum(impulses.amplitude) == pytest.approx(1.0, abs=1e-15)
    assert np.all(impulses.amplitude > 0)
    assert impulses.time_s[0] == 0.0
    assert float(residual_vibration(impulses, 2.7, zeta)) < 1e-12


@pytest.mark.parametrize('zeta', DAMPINGS)
def test_zvd_has_a_flat_sensitivity_curve_at_the_design_frequency(zeta):
    mode = Mode(2.7, zeta)
    step = 1e-4 * 2.7
    v = residual_vibration(zvd_shaper(mode), [2.7 - step, 2.7 + step], zeta)
    # Zero value and zero slope: V grows quadratically, ZV's linearly.
    assert np.max(v) < 1e-6
    assert np.min(residual_vibration(zv_shaper(mode), [2.7 - step, 2.7 + step], zeta)) > 1e-5


def test_textbook_values_without_damping():
    zv = zv_shaper(Mode(2.0, 0.0))
    zvd = zvd_shaper(Mode(2.0, 0.0))
    assert zv.time_s.tolist() == [0.0, 0.25] and zv.amplitude.tolist() == [0.5, 0.5]
    assert zvd.time_s.tolist() == [0.0, 0.25, 0.5]
    assert zvd.amplitude.tolist() == [0.25, 0.5, 0.25]


def test_damped_zv_amplitudes_follow_k():
    zeta = 0.1
    k = math.exp(-zeta * math.pi / math.sqrt(1 - zeta**2))
    zv = zv_shaper(Mode(1.0, zeta))
    assert zv.amplitude.tolist() == pytest.approx([1 / (1 + k), k / (1 + k)], rel=1e-15)
    assert zv.time_s[1] == pytest.approx(0.5 / math.sqrt(1 - zeta**2), rel=1e-15)


@pytest.mark.parametrize('zeta', [0.0, 0.02, 0.1])
def test_robust_shapers_have_wider_bands_than_zv(zeta):
    mode = Mode(3.0, zeta)
    widths = {}
    for name, shaper in SHAPERS.items():
        low, high = insensitivity_band(shaper(mode), mode, 0.05)
        assert low < 3.0 < high
        widths[name] = (high - low) / 3.0
    assert widths['zv'] < 0.08 and widths['zvd'] > 3 * widths['zv']
    assert widths['ei'] > 1.3 * widths['zvd']


def test_several_modes_are_each_cancelled():
    modes = [Mode(1.7, 0.02), Mode(9.3, 0.05), Mode(23.0, 0.01)]
    for kind in SHAPERS:
        impulses = design_shaper(kind, modes)
        assert np.sum(impulses.amplitude) == pytest.approx(1.0, abs=1e-14)
        assert np.all(np.diff(impulses.time_s) > 0)
        single = [SHAPERS[kind](m) for m in modes]
        assert impulses.duration_s == pytest.approx(sum(s.duration_s for s in single), rel=1e-12)
        for mode in modes:
            left = float(residual_vibration(impulses, mode.frequency_hz, mode.damping_ratio))
            assert left <= (0.05 if kind == 'ei' else 0.0) + 1e-9


@pytest.mark.parametrize(
    ('kind', 'modes', 'problem'),
    [
        ('zvdd', [Mode(1.0, 0.0)], "unknown shaper 'zvdd' (choose from zv, zvd, ei)"),
        ('zv', [], 'a shaper needs at least one mode'),
    ],
)
def test_bad_designs_are_one_line(kind, modes, problem):
    with pytest.raises(LumpbeamError) as caught:
        design_shaper(kind, modes)
    assert str(caught.value) == problem
