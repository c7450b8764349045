import math
from dataclasses import replace

import numpy as np
import pytest

from lumpbeam_ros.diagnose.candidates import effect_candidates, nominal_candidate
from lumpbeam_ros.diagnose.workflow import nominal_form
from lumpbeam_ros.model.parameters import EFFECT_PARAMETERS, BeamParameters

BEAM = BeamParameters()


def test_one_candidate_per_spec_effect():
    candidates = effect_candidates(BEAM)
    assert [c.name for c in candidates] == list(EFFECT_PARAMETERS)
    assert all(c.parameter == EFFECT_PARAMETERS[c.name] for c in candidates)
    assert all(c.search[0] < c.start < c.search[1] for c in candidates)


@pytest.mark.parametrize('candidate', effect_candidates(BEAM), ids=lambda c: c.name)
def test_log_parameters_map_to_the_beam(candidate):
    x = np.array([math.log(1.1), math.log(0.5), math.log(candidate.start / candidate.scale)])
    beam = candidate.beam(BEAM, x)
    assert beam.k_total_nm_per_rad == pytest.approx(1.1 * BEAM.k_total_nm_per_rad)
    assert beam.beta_identified == pytest.approx(0.5 * BEAM.beta_identified)
    assert beam.effects.active() == {candidate.name: pytest.approx(candidate.start)}
    assert candidate.values(BEAM, x)[candidate.parameter] == pytest.approx(candidate.start)
    assert candidate.physical(BEAM, x)
    lo, hi = candidate.bounds(BEAM)
    assert not candidate.physical(BEAM, np.r_[x[:2], hi[2]])  # pinned at the bound
    assert not candidate.physical(BEAM, np.r_[x[0], lo[1], x[2]])


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
        ('base_compliance', 500.0, False),
    ],
)
def test_absurd_magnitudes_are_unphysical(name, value, physical):
    candidate = next(c for c in effect_candidates(BEAM) if c.name == name)
    x = np.array([0.0, 0.0, math.log(value / candidate.scale)])
    assert candidate.physical(BEAM, x) is physical


def test_nominal_keeps_configured_effects_and_has_two_parameters():
    beam = replace(BEAM, effects=BEAM.effects.with_effect('added_mass', 0.2))
    nominal = nominal_candidate()
    assert nominal.n_parameters == 2
    assert nominal.beam(beam, np.zeros(2)).effects.active() == {'added_mass': 0.2}
    latency = effect_candidates(beam)[-1]
    both = latency.beam(beam, np.array([0.0, 0.0, 0.0])).effects.active()
    assert both == {'added_mass': 0.2, 'sensor_latency': pytest.approx(0.01)}


def test_an_analytic_beam_is_rewritten_with_the_same_joints():
    analytic = replace(BEAM, stiffness_source='analytic', c_total=0.0)
    rewritten = nominal_form(analytic)
    assert rewritten.stiffness_source == 'identified'
    np.testing.assert_allclose(rewritten.joint_stiffness(), analytic.joint_stiffness())
    np.testing.assert_allclose(rewritten.joint_damping(), analytic.joint_damping())
    assert rewritten.c_total > 0.0
