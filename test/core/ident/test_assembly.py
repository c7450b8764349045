"""An identification put together: derived figures (B.12, B.22), the grade, the result's form."""

import math

import pytest

from lumpbeam_ros.core.ident.assembly import released_load
from lumpbeam_ros.core.ident.identification import Status
from lumpbeam_ros.core.ident.identify import identify
from lumpbeam_ros.core.ident.release import Release
from lumpbeam_ros.core.ident.samples import clean_window
from lumpbeam_ros.core.ident.settings import IdentifierConfig
from lumpbeam_ros.core.model.parameters import BeamParameters

from .conftest import pose_window

BEAM = BeamParameters()


def test_the_released_load_is_the_readings_else_the_configured_one():
    config = IdentifierConfig()
    assert released_load(Release(), config) == config.assumed_load_kg
    assert released_load(Release(load_kg=3.5), config) == 3.5


def test_derived_figures_follow_the_paper(drop_case):
    trajectory, truth = drop_case()
    r = identify(pose_window(trajectory, True), BEAM)
    # B.21 links the decrement and the damping ratio; B.22 gives c_tE; f_n = f_d/sqrt(1-z^2).
    assert r.estimates.damping_ratio.value == pytest.approx(
        1 / math.sqrt(1 + (2 * math.pi / r.estimates.log_decrement.value) ** 2)
    )
    assert r.estimates.damping_total.value == pytest.approx(
        2 * r.estimates.damping_ratio.value * 2 * math.pi * r.estimates.damped_frequency_hz.value
    )
    assert r.estimates.natural_frequency_hz.value == pytest.approx(
        r.estimates.damped_frequency_hz.value / math.sqrt(1 - r.estimates.damping_ratio.value**2)
    )
    force = 4.5 * BEAM.gravity_mps2
    assert r.estimates.stiffness_vertical_n_per_m.value == pytest.approx(
        force / r.release.static_deflection_m.value
    )
    assert r.estimates.stiffness_total_nm_per_rad.value == pytest.approx(
        2 * force * BEAM.length_m**2 / (3 * r.release.static_deflection_m.value)
    )
    # The cross-checks agree with the headline figures within their own accuracy.
    assert r.cross_checks.damping_ratio_b20.value == pytest.approx(
        r.estimates.damping_ratio.value, rel=0.05
    )
    assert r.cross_checks.natural_frequency_pencil_hz == pytest.approx(
        r.estimates.natural_frequency_hz.value, rel=1e-3
    )
    assert r.cross_checks.stiffness_total_from_pitch_nm_per_rad.value == pytest.approx(
        truth.stiffness_total_nm_per_rad, rel=0.01
    )
    assert r.cross_checks.stiffness_vertical_from_frequency_n_per_m.value == pytest.approx(
        r.estimates.stiffness_vertical_n_per_m.value, rel=0.05
    )


def test_result_carries_the_spec_keys(drop_case):
    trajectory, _ = drop_case()
    r = identify(pose_window(trajectory, True), BEAM)
    d = r.as_dict()
    spec = [
        'natural_frequency_hz',
        'damped_frequency_hz',
        'damping_ratio',
        'log_decrement',
        'stiffness_total_nm_per_rad',
        'stiffness_vertical_n_per_m',
        'damping_total',
    ]
    for key in spec:
        assert math.isfinite(d[key]) and math.isfinite(d[f'{key}_std']) and d[f'{key}_std'] > 0
    for key in [
        'window_start_s',
        'window_end_s',
        'cycles',
        'release_time_s',
        'static_deflection_m',
    ]:
        assert math.isfinite(d[key])
    assert d['status'] == 'OK' and d['method'].startswith('nls_damped_sinusoid')
    assert 29 < d['cycles'] < 31
    pairs = dict(r.key_values())
    assert float(pairs['natural_frequency_hz']) == r.estimates.natural_frequency_hz.value
    assert pairs['natural_frequency_hz'] == repr(r.estimates.natural_frequency_hz.value)
    assert 'status' not in pairs and pairs['method'] == r.method


def test_short_decay_warns(drop_case):
    trajectory, truth = drop_case()
    part = trajectory.between(0.0, 2.6)
    r = identify(clean_window(part.t, part.z, part.pitch), BEAM)
    assert r.status == Status.WARN and 'cycles' in r.message
    assert r.estimates.natural_frequency_hz.value == pytest.approx(
        truth.natural_frequency_hz, rel=0.01
    )


def test_window_without_release_gives_dynamics_but_warns_on_stiffness(drop_case):
    trajectory, truth = drop_case()
    part = trajectory.between(3.0, 12.0)
    r = identify(clean_window(part.t, part.z, part.pitch), BEAM)
    assert r.status == Status.WARN and 'stiffness' in r.message
    assert math.isnan(r.estimates.stiffness_total_nm_per_rad.value)
    assert r.estimates.natural_frequency_hz.value == pytest.approx(
        truth.natural_frequency_hz, rel=1e-3
    )
