"""End to end on hidden-effect data: the right name, its parameter, the gap closed.

Each record is the synthetic drop test (doc/interfaces.md defaults) with one effect of
the library hidden at a realistic strength and 20 um of pose noise; the diagnoses run once per
module and every test reads them.
"""

from dataclasses import replace

import numpy as np
import pytest

from lumpbeam_ros.core.diagnose.candidates import (
    SEARCHED_EFFECTS,
    effect_candidates,
    nominal_candidate,
)
from lumpbeam_ros.core.diagnose.fitting import FitProblem
from lumpbeam_ros.core.diagnose.measurement import record_from_trajectory
from lumpbeam_ros.core.diagnose.selection import Model
from lumpbeam_ros.core.diagnose.workflow import diagnose, dry_friction_start, nominal_form
from lumpbeam_ros.core.model.parameters import EFFECT_PARAMETERS, load_beam_config
from lumpbeam_ros.core.model.simulate import simulate_loads
from lumpbeam_ros.core.model.trajectory import TipTrajectory
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, simulate_experiment

from .hardening import simulate_hardening_drop

# Nine whole diagnoses (about a minute and a half on an idle machine): the slow suite.
pytestmark = pytest.mark.slow

NOISE_M = 20e-6

#: Realistic strengths: the hidden effect and its true parameter.
HIDDEN = {
    'coulomb_friction': 1.0,
    'base_compliance': 2e4,
    'added_mass': 0.3,
    'quadratic_drag': 0.5,
    'sensor_latency': 0.015,
}

#: Clamp hardening strong enough that the frequency falls ~0.15 % as the swing decays.
CUBIC_NM_PER_RAD3 = 5e8


def _noisy(trajectory: TipTrajectory, seed: int) -> TipTrajectory:
    rng = np.random.default_rng(seed)
    noise = NOISE_M * rng.standard_normal((2, len(trajectory)))
    return replace(trajectory, z=trajectory.z + noise[0], pitch=trajectory.pitch + noise[1])


@pytest.fixture(scope='module')
def diagnoses():
    beam, drop = load_beam_config()
    events = [(drop.release_time_s, 0.0)]
    out = {}
    cases = [('nominal', {})] + [(name, {name: value}) for name, value in HIDDEN.items()]
    for seed, (label, effects) in enumerate(cases):
        measured, _ = simulate_experiment(beam, drop, SynthOptions(effects=effects))
        record = record_from_trajectory(_noisy(measured, seed), events, drop.load_kg)
        out[label] = diagnose(record, beam)
    # A beam stiffer and more damped than configured, nothing else: the refit absorbs it.
    retuned = replace(beam, k_total_nm_per_rad=4300.0, beta_identified=20.0)
    measured, _ = simulate_experiment(retuned, drop, SynthOptions())
    out['retuned'] = diagnose(record_from_trajectory(_noisy(measured, 97), events, 4.5), beam)
    # A 12 kg "bracket": the added-mass fit explains it, but with an absurd mass.
    measured, _ = simulate_experiment(beam, drop, SynthOptions(effects={'added_mass': 12.0}))
    out['absurd'] = diagnose(record_from_trajectory(_noisy(measured, 98), events, 4.5), beam)
    hard = simulate_hardening_drop(beam, drop, CUBIC_NM_PER_RAD3)
    out['hardening'] = diagnose(
        record_from_trajectory(_noisy(hard, 99), events, drop.load_kg), beam
    )
    return out


@pytest.mark.parametrize('effect', sorted(HIDDEN))
def test_names_the_hidden_effect_fits_it_and_closes_the_gap(diagnoses, effect):
    d = diagnoses[effect]
    assert d.missing_effect == effect, d.decision.reason
    parameter = EFFECT_PARAMETERS[effect]
    assert set(d.effect_parameters) == {parameter}
    assert d.effect_parameters[parameter] == pytest.approx(HIDDEN[effect], rel=0.25)
    assert d.gap_after.rms_m <= 0.3 * d.gap_before.rms_m
    # The error floor is the white noise: the free-form decay absorbs every envelope.
    assert d.noise_z_m == pytest.approx(NOISE_M, rel=0.1)
    # Down to the noise: the augmented model leaves white noise of the right size.
    assert d.gap_after.rms_m == pytest.approx(NOISE_M, rel=0.15)
    assert d.augmented_beam.effects.value(effect) == d.effect_parameters[parameter]
    assert [s.name for s in d.candidates][0] == effect
    assert sorted(s.name for s in d.candidates) == sorted(SEARCHED_EFFECTS)


@pytest.mark.parametrize('effect', sorted(HIDDEN))
def test_refit_nominal_parameters_return_to_the_truth_with_the_effect(diagnoses, effect):
    beam, _ = load_beam_config()
    augmented = diagnoses[effect].augmented_beam
    assert augmented.k_total_nm_per_rad == pytest.approx(beam.k_total_nm_per_rad, rel=0.02)
    assert augmented.beta_identified == pytest.approx(beam.beta_identified, rel=0.1)


def test_nominal_data_gets_none(diagnoses):
    d = diagnoses['nominal']
    assert d.missing_effect == 'none', d.decision.reason
    assert d.effect_parameters == {}
    assert d.gap_after == d.gap_before
    assert d.gap_configured.rms_m == pytest.approx(d.gap_before.rms_m, rel=0.01)
    assert d.gap_before.rms_m == pytest.approx(NOISE_M, rel=0.15)
    assert abs(d.gap_before.frequency_error) < 1e-3
    assert d.nominal.record_chi2 == pytest.approx(1.0, abs=0.15)


def test_a_mistuned_configuration_is_refit_not_blamed_on_an_effect(diagnoses):
    d = diagnoses['retuned']
    assert d.missing_effect == 'none', d.decision.reason
    assert d.nominal_beam.k_total_nm_per_rad == pytest.approx(4300.0, rel=0.01)
    assert d.nominal_beam.beta_identified == pytest.approx(20.0, rel=0.05)
    assert d.gap_before.rms_m == pytest.approx(NOISE_M, rel=0.15)
    # As configured, the model was off by the retuning (about 5 % in frequency).
    assert d.gap_configured.frequency_error == pytest.approx(-0.05, abs=0.01)
    assert d.gap_configured.rms_m > 100 * NOISE_M


def test_an_effect_that_needs_an_absurd_parameter_is_unexplained(diagnoses):
    d = diagnoses['absurd']
    assert d.missing_effect == 'unexplained', d.decision.reason
    assert 'unphysical' in d.decision.reason
    best = d.candidates[0]
    assert best.name == 'added_mass' and not best.physical
    assert d.effect_parameters == {}
    assert d.augmented_beam == d.nominal_beam


def test_a_hardening_clamp_is_unexplained(diagnoses):
    d = diagnoses['hardening']
    assert d.missing_effect == 'unexplained', d.decision.reason
    assert d.effect_parameters == {}
    # The gap is real: many times the noise, and no candidate brings it down to it.
    assert d.gap_before.rms_m > 5 * NOISE_M
    assert min(s.record_chi2 for s in d.candidates) > 5.0


def test_signatures_point_at_their_effects(diagnoses):
    sig = {label: d.signatures for label, d in diagnoses.items()}
    # A late sensor shows the drop late against the load event.
    assert sig['sensor_latency'].time_shift_s == pytest.approx(0.015, abs=1.5e-3)
    assert abs(sig['nominal'].time_shift_s) < 1e-3
    # A compliant mount rotates the tip less per unit of z than a softer beam does.
    assert sig['base_compliance'].slope_ratio_error < -0.03
    assert abs(sig['nominal'].slope_ratio_error) < 2e-3
    # An added mass leaves the static levels off: the nominal refit softens the beam to
    # match the frequency and then sags too far under the load (the drop itself matches).
    assert abs(sig['added_mass'].static_offset_before_m) > 1e-3
    assert abs(sig['nominal'].static_offset_before_m) < 1e-5
    # A hardening spring slows down as the swing decays; linear effects do not.
    assert sig['hardening'].frequency_drift > 5e-4
    assert abs(sig['nominal'].frequency_drift) < 1e-4
    # Dry friction adds a constant loss per cycle, drag one that grows with the swing.
    assert sig['nominal'].envelope == 'exponential'
    assert sig['coulomb_friction'].envelope == 'linear'
    assert sig['quadratic_drag'].envelope == 'amplitude_dependent'


def test_json_form_has_the_spec_keys(diagnoses):
    d = diagnoses['added_mass'].as_dict()
    assert list(d)[:5] == [
        'missing_effect',
        'effect_parameters',
        'gap_before',
        'gap_after',
        'candidates',
    ]
    for gap in ('gap_before', 'gap_after'):
        assert set(d[gap]) == {'rms_m', 'max_m', 'frequency_error', 'damping_error'}
    assert all(set(c) == {'name', 'parameters', 'score'} for c in d['candidates'])
    assert d['candidates'][0]['parameters']['mass_kg'] == pytest.approx(0.3, rel=0.25)


@pytest.mark.parametrize('torque', [0.0, 0.5])
def test_dry_friction_starts_where_the_envelopes_put_it(torque):
    # A noise-free drop with dry friction (or none): the nominal fit mimics it with extra
    # damping; the envelopes give back the torque and the configured damping.
    beam, drop = load_beam_config()
    nominal = nominal_form(beam)
    hidden = replace(nominal, effects=nominal.effects.with_effect('coulomb_friction', torque))
    t = np.arange(0.0, 6.0, 1.0 / 180.0)
    events = [(1.0, 0.0)]
    trajectory = simulate_loads(hidden, t, events, drop.load_kg)
    record = record_from_trajectory(trajectory, events, drop.load_kg)
    problem = FitProblem(record, nominal, 20e-6, 1e-5)
    fit = problem.fit(nominal_candidate(), np.zeros(2))
    friction = next(c for c in effect_candidates(nominal) if c.name == 'coulomb_friction')
    x = dry_friction_start(problem, Model(), fit.x, friction, np.inf)
    assert x is not None
    assert friction.value(x) == pytest.approx(torque, abs=0.05 * max(torque, 0.2))
    assert abs(x[1]) < 0.05  # beta back at the configured one
    if torque:
        assert fit.x[1] > 0.1  # which the nominal fit had raised
