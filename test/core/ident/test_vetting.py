"""The last check before publishing: no confident unphysical mode, no uncertainty-free one."""

import math
from dataclasses import replace

import pytest

from lumpbeam_ros.core.ident.identification import (
    Estimate,
    Estimates,
    FitQuality,
    Identification,
    IdentifiedMode,
    Status,
)
from lumpbeam_ros.core.ident.vetting import mode_defect, vetted

NOISY, NOISELESS = 20e-6, 1e-13


def _mode(f=3.5, f_std=2e-4, zeta=0.02, zeta_std=1e-4):
    return IdentifiedMode(Estimate(f, f_std), Estimate(zeta, zeta_std), 1e-3)


def _result(*modes, status=Status.OK, noise=NOISY):
    first = modes[0]
    return Identification(
        status,
        'fit ok',
        estimates=Estimates(
            natural_frequency_hz=first.natural_frequency_hz, damping_ratio=first.damping_ratio
        ),
        quality=FitQuality(residual_rms_m=noise),
        modes=modes,
    )


@pytest.mark.parametrize(
    ('mode', 'noise', 'defect'),
    [
        (_mode(), NOISY, None),
        (_mode(zeta=-1e-4, zeta_std=3e-4), NOISY, None),  # consistent with 0: honest
        (_mode(zeta=-0.00052, zeta_std=4.9e-9), NOISY, 'a free decay grows no mode'),
        (_mode(f=20.91, f_std=1.9e-11, zeta=0.99992), NOISY, 'no uncertainty'),
        (_mode(f_std=0.0), NOISY, 'no uncertainty'),
        (_mode(zeta_std=0.0), NOISY, 'no uncertainty'),
        (_mode(f_std=1e-13, zeta_std=1e-12), NOISELESS, None),  # exact data, exact modes
        (_mode(f=math.nan), NOISY, 'not a mode'),
        (_mode(f=-3.0), NOISY, 'not a mode'),
    ],
)
def test_a_mode_is_published_only_when_a_free_decay_can_have_it(mode, noise, defect):
    found = mode_defect(mode, noise)
    assert (found is None) if defect is None else (defect in found)


@pytest.mark.parametrize('status', [Status.OK, Status.WARN])
def test_a_defective_first_mode_makes_an_error_with_no_figures(status):
    result = vetted(_result(_mode(zeta=-0.00052, zeta_std=4.9e-9), _mode(f=19.0), status=status))
    assert result.status == Status.ERROR and result.modes == ()
    assert result.message.startswith('not published: damping ratio -0.00052')
    assert math.isnan(result.estimates.natural_frequency_hz.value)


def test_a_defective_higher_mode_is_left_out_with_the_reason():
    good, bad = _mode(), _mode(f=20.91, f_std=1.9e-11, zeta=0.99992)
    result = vetted(_result(good, bad, _mode(f=40.0, f_std=0.01)))
    assert result.status == Status.OK and [m.natural_frequency_hz.value for m in result.modes] == [
        3.5,
        40.0,
    ]
    assert result.message.startswith('fit ok; mode 2 left out: 20.91 +- 1.9e-11 Hz')


def test_a_sound_or_failed_identification_passes_unchanged():
    sound = _result(_mode(), _mode(f=19.0, f_std=0.01))
    assert vetted(sound) is sound
    failed = replace(sound, status=Status.ERROR)
    assert vetted(failed) is failed
