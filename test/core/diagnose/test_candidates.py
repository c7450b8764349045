import math
from dataclasses import replace

import numpy as np
import pytest

from lumpbeam_ros.core.diagnose.candidates import (
    SEARCHED_EFFECTS,
    effect_candidates,
    nominal_candidate,
)
from lumpbeam_ros.core.diagnose.workflow import nominal_form
from lumpbeam_ros.core.model.parameters import EFFECT_PARAMETERS, BeamParameters

BEAM = BeamParameters()
K_CLAMP = float(BEAM.joint_stiffness()[0])


def _candidate(name):
    return next(c for c in effect_candidates(BEAM) if c.name == name)


def _x(candidate, value, k_factor=1.0, beta_factor=1.0):
    """x for an effect's contract parameter value."""
    strength = candidate.reference / value if candidate.reciprocal else value - candidate.offset
    return np.array([math.log(k_factor), math.log(beta_factor), strength / candidate.scale])


def test_one_candidate_per_spec_effect_and_the_nominal_model_at_strength_zero():
    candidates = effect_candidates(BEAM)
    assert [c.name for c in candidates] == list(SEARCHED_EFFECTS)
    assert set(SEARCHED_EFFECTS) <= set(EFFECT_PARAMETERS)
    assert all(c.parameter == EFFECT_PARAMETERS[c.name] for c in candidates)
    for c in candidates:
        lo, hi = c.bounds()
        assert lo[2] == (-hi[2] if c.signed else 0.0) and lo[2] < c.start / c.scale < hi[2]
        assert c.beam(BEAM, np.zeros(3)) == BEAM  # strength 0: the nominal beam


@pytest.mark.parametrize(
    ('name', 'value'),
    [
        ('base_compliance', 2e4),
        ('coulomb_friction', 1.0),
        ('quadratic_drag', 0.5),
        ('added_mass', 0.3),
        ('sensor_latency', 0.015),
        ('cubic_stiffness', 1e8),
        ('cubic_stiffness', -1e8),
        ('sensor_scale', 1.05),
        ('sensor_scale', 0.95),
        ('mount_tilt', 0.05),
        ('mount_tilt', -0.05),
    ],
)
def test_parameters_map_to_the_beam(name, value):
    candidate = _candidate(name)
    x = _x(candidate, value, 1.1, 0.5)
    beam = candidate.beam(BEAM, x)
    assert beam.k_total_nm_per_rad == pytest.approx(1.1 * BEAM.k_total_nm_per_rad)
    assert beam.beta_identified == pytest.approx(0.5 * BEAM.beta_identified)
    assert beam.effects.active() == {name: pytest.approx(value)}
    assert candidate.values(BEAM, x)[candidate.parameter] == pytest.approx(value)
    assert candidate.physical(x)
    lo, hi = candidate.bounds()
    assert not candidate.physical(np.r_[x[:2], hi[2]])  # pinned at the search bound
    assert not candidate.physical(np.r_[x[0], lo[1], x[2]])  # damping at its bound


def test_a_rigid_mount_is_infinitely_stiff_and_switched_off():
    candidate = _candidate('base_compliance')
    assert math.isinf(candidate.value(np.zeros(3)))
    assert candidate.beam(BEAM, np.zeros(3)).effects.k_base_nm_per_rad == 0.0


@pytest.mark.parametrize(
    ('name', 'value', 'physical'),
    [
        ('added_mass', 0.3, True),
        ('added_mass', 40.0, False),
        ('coulomb_friction', 1.0, True),
        ('coulomb_friction', 30.0, False),
        ('sensor_latency', 0.015, True),
        ('sensor_latency', 0.6, False),
        ('quadratic_drag', 0.5, True),
        ('quadratic_drag', 200.0, False),
        ('base_compliance', 2e4, True),
        ('base_compliance', K_CLAMP / 50.0, False),
        ('sensor_scale', 1.2, True),
        ('sensor_scale', 0.6, False),
        ('mount_tilt', -0.1, True),
        ('mount_tilt', 0.5, False),
        ('cubic_stiffness', 1e8, True),
        ('cubic_stiffness', -1e10, False),
    ],
)
def test_absurd_magnitudes_are_unphysical(name, value, physical):
    candidate = _candidate(name)
    assert candidate.physical(_x(candidate, value)) is physical


def test_nominal_keeps_configured_effects_and_has_two_parameters():
    beam = replace(BEAM, effects=BEAM.effects.with_effect('added_mass', 0.2))
    nominal = nominal_candidate()
    assert nominal.n_parameters == 2
    assert nominal.beam(beam, np.zeros(2)).effects.active() == {'added_mass': 0.2}
    latency = _candidate('sensor_latency')
    both = latency.beam(beam, np.array([0.0, 0.0, 1.0])).effects.active()
    assert both == {'added_mass': 0.2, 'sensor_latency': pytest.approx(0.01)}


def test_an_analytic_beam_is_rewritten_with_the_same_joints():
    analytic = replace(BEAM, stiffness_source='analytic', c_total=0.0)
    rewritten = nominal_form(analytic)
    assert rewritten.stiffness_source == 'identified'
    np.testing.assert_allclose(rewritten.joint_stiffness(), analytic.joint_stiffness())
    np.testing.assert_allclose(rewritten.joint_damping(), analytic.joint_damping())
    assert rewritten.c_total > 0.0
