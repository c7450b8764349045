import math
from dataclasses import replace

import numpy as np
import pytest

from lumpbeam_ros.core.diagnose.candidates import effect_candidates, nominal_candidate
from lumpbeam_ros.core.diagnose.fitting import (
    DIFF_STEP,
    DIVERGED_RESIDUAL,
    FitProblem,
    forward_jacobian,
)
from lumpbeam_ros.core.diagnose.measurement import make_record
from lumpbeam_ros.core.diagnose.selection import Model
from lumpbeam_ros.core.diagnose.workflow import nominal_form
from lumpbeam_ros.core.model.parameters import BeamParameters
from lumpbeam_ros.core.model.simulate import WarmStart, simulate_loads

NOMINAL = nominal_form(BeamParameters())
RATE_HZ = 180.0
EVENTS = [(0.5, 0.0)]  # 4.5 kg released at 0.5 s
SIGMA_Z, SIGMA_PITCH = 20e-6, 1e-5


def _beam(k_factor=1.0, beta_factor=1.0, **effects):
    beam = replace(
        NOMINAL,
        k_total_nm_per_rad=NOMINAL.k_total_nm_per_rad * k_factor,
        beta_identified=NOMINAL.beta_identified * beta_factor,
    )
    for name, value in effects.items():
        beam = replace(beam, effects=beam.effects.with_effect(name, value))
    return beam


def _record(beam, t=None, noise=0.0, seed=0, z_bias=None):
    """A record of a drop of ``beam``, simulated by the model at its stamps."""
    t = np.arange(0.0, 3.0, 1.0 / RATE_HZ) if t is None else t
    exact = simulate_loads(beam, t, EVENTS, 4.5)
    rng = np.random.default_rng(seed)
    z = exact.z + noise * SIGMA_Z * rng.standard_normal(t.size)
    pitch = exact.pitch + noise * SIGMA_PITCH * rng.standard_normal(t.size)
    return make_record(t, z + (0.0 if z_bias is None else z_bias), pitch, 4.5, EVENTS)


def _problem(record):
    return FitProblem(record, NOMINAL, SIGMA_Z, SIGMA_PITCH)


# -- residuals -------------------------------------------------------------------------------


def test_the_beam_that_made_the_record_leaves_no_residual():
    beam = _beam(1.04, 1.5)
    problem = _problem(_record(beam))
    residuals = problem.residuals(problem.simulate(beam))
    assert residuals.size == 2 * len(problem.record) and problem.simulations == 1
    np.testing.assert_allclose(residuals, 0.0, atol=1e-9)


@pytest.mark.parametrize(('sigma_z', 'sigma_pitch'), [(20e-6, 1e-5), (1e-3, 2e-4)])
def test_residuals_are_model_minus_measurement_in_noise_sigmas(sigma_z, sigma_pitch):
    record = _record(NOMINAL)
    shifted = make_record(record.t, record.z + 3e-5, record.pitch - 2e-5, 4.5, EVENTS)
    problem = FitProblem(shifted, NOMINAL, sigma_z, sigma_pitch)
    residuals = problem.residuals(problem.simulate(NOMINAL))
    n = len(record)
    np.testing.assert_allclose(residuals[:n], -3e-5 / sigma_z, rtol=1e-6)
    np.testing.assert_allclose(residuals[n:], 2e-5 / sigma_pitch, rtol=1e-6)


@pytest.mark.parametrize(
    ('start_s', 'end_s'), [(-math.inf, math.inf), (1.0, math.inf), (0.4, 2.0)]
)
def test_residuals_cover_the_stamps_between_start_and_end(start_s, end_s):
    problem = _problem(_record(NOMINAL))
    trajectory = problem.simulate(NOMINAL, end_s)
    t = problem.record.t
    assert len(trajectory) == np.count_nonzero(t <= end_s)
    residuals = problem.residuals(trajectory, start_s)
    assert residuals.size == 2 * np.count_nonzero((t >= start_s) & (t <= end_s))


def _with_tracking_loss():
    """Stamps with 0.2 s of frames missing at 1.5 s: two tracked stretches."""
    t = np.arange(0.0, 3.0, 1.0 / RATE_HZ)
    t = t[(t < 1.5) | (t >= 1.7)]
    return t, t >= 1.7


def test_a_later_tracked_stretch_is_compared_up_to_its_own_offset():
    t, second = _with_tracking_loss()
    problem = _problem(_record(NOMINAL, t, z_bias=np.where(second, 50e-6, 0.0)))
    assert problem.record.tracked_segments().max() == 1
    residuals = problem.residuals(problem.simulate(NOMINAL))
    np.testing.assert_allclose(residuals, 0.0, atol=1e-9)


def test_the_first_stretch_keeps_its_absolute_level():
    t, second = _with_tracking_loss()
    problem = _problem(_record(NOMINAL, t, z_bias=np.where(second, 0.0, 50e-6)))
    rz = problem.residuals(problem.simulate(NOMINAL))[: t.size]
    np.testing.assert_allclose(rz[~second], -50e-6 / SIGMA_Z, rtol=1e-6)
    np.testing.assert_allclose(rz[second], 0.0, atol=1e-9)


def test_a_record_tracked_throughout_is_compared_as_it_is():
    problem = _problem(_record(NOMINAL, z_bias=50e-6))
    rz = problem.residuals(problem.simulate(NOMINAL))[: len(problem.record)]
    np.testing.assert_allclose(rz, -50e-6 / SIGMA_Z, rtol=1e-6)


# -- fit -------------------------------------------------------------------------------------


@pytest.mark.parametrize(('k_factor', 'beta_factor'), [(1.04, 1.5), (0.93, 0.7)])
def test_the_nominal_fit_finds_the_stiffness_and_damping_of_the_record(k_factor, beta_factor):
    problem = _problem(_record(_beam(k_factor, beta_factor), noise=1.0))
    fit = problem.fit(nominal_candidate(), np.zeros(2))
    np.testing.assert_allclose(fit.x, [math.log(k_factor), math.log(beta_factor)], atol=2e-3)
    assert fit.name == 'nominal' and fit.physical
    assert fit.beam.k_total_nm_per_rad == pytest.approx(
        NOMINAL.k_total_nm_per_rad * k_factor, 2e-3
    )
    # Down to the noise: chi2 of 2n residuals scatters by sqrt(2 * 2n) about 2n.
    assert fit.n_residuals == 2 * len(problem.record)
    assert abs(fit.chi2 - fit.n_residuals) < 4 * math.sqrt(2 * fit.n_residuals)
    assert fit.reduced_chi2 == fit.chi2 / fit.n_residuals
    assert fit.evaluations == problem.simulations > 2


def test_a_fit_up_to_an_end_uses_only_those_samples():
    problem = _problem(_record(_beam(1.04, 1.5), noise=1.0))
    fit = problem.fit(nominal_candidate(), np.zeros(2), end_s=2.0, max_evaluations=30)
    assert fit.n_residuals == 2 * np.count_nonzero(problem.record.t <= 2.0)
    assert fit.evaluations == problem.simulations


def test_an_effect_fit_finds_the_latency_of_the_record():
    latency = next(c for c in effect_candidates(NOMINAL) if c.name == 'sensor_latency')
    problem = _problem(_record(_beam(1.02, 1.2, sensor_latency=0.012), noise=1.0))
    fit = problem.fit(latency, latency.start_x(np.zeros(2)))
    assert latency.value(fit.x) == pytest.approx(0.012, rel=0.05)
    assert fit.beam.effects.active() == {'sensor_latency': pytest.approx(0.012, rel=0.05)}
    assert fit.physical


def test_a_record_beyond_the_search_range_is_not_physical():
    # Six times stiffer than nominal: the refit stops at its bound (STIFFNESS_FACTORS).
    problem = _problem(_record(_beam(6.0), noise=1.0))
    fit = problem.fit(nominal_candidate(), np.zeros(2))
    lo, hi = nominal_candidate().bounds()
    assert fit.x[0] == pytest.approx(hi[0], abs=1e-2) and not fit.physical


def test_a_start_outside_the_bounds_is_clipped_into_them():
    problem = _problem(_record(NOMINAL, noise=1.0))
    fit = problem.fit(nominal_candidate(), np.array([10.0, -10.0]), max_evaluations=5)
    lo, hi = nominal_candidate().bounds()
    assert np.all(fit.x >= lo) and np.all(fit.x <= hi) and math.isfinite(fit.chi2)


@pytest.mark.parametrize('k_base', [5.0, 50.0])
def test_a_mount_too_soft_to_carry_the_beam_is_a_bad_fit_not_an_error(k_base):
    problem = FitProblem(_record(NOMINAL), NOMINAL, SIGMA_Z, SIGMA_PITCH)
    candidate = next(c for c in effect_candidates(NOMINAL) if c.name == 'base_compliance')
    x = np.r_[0.0, 0.0, candidate.reference / k_base / candidate.scale]
    residuals = problem.model_residuals(Model((candidate,)), x)
    assert residuals.size == 2 * len(problem.record)
    np.testing.assert_array_equal(residuals, DIVERGED_RESIDUAL)


def test_a_fit_starts_from_the_better_of_its_starts_and_remembers_what_it_simulated():
    problem = _problem(_record(_beam(1.04, 1.5), noise=1.0))
    truth = np.array([math.log(1.04), math.log(1.5)])
    far = problem.fit(nominal_candidate(), np.zeros(2))
    problem.simulations = 0
    near = problem.fit(nominal_candidate(), np.array([0.3, -1.0]), alternatives=[truth + 1e-3])
    np.testing.assert_allclose(near.x, far.x, atol=1e-4)
    # Both starts are simulated once; the least squares' own first call is remembered.
    assert near.evaluations < far.evaluations
    residuals = problem.model_residuals(nominal_candidate(), near.x)
    before = problem.simulations
    again = problem.model_residuals(nominal_candidate(), near.x)
    assert problem.simulations == before and np.array_equal(again, residuals)
    again[:] = 0.0  # a caller's copy: the memory keeps its own
    assert not np.array_equal(problem.model_residuals(nominal_candidate(), near.x), again)


def test_a_new_nominal_beam_forgets_the_remembered_residuals():
    problem = _problem(_record(_beam(1.04, 1.5)))
    first = problem.model_residuals(nominal_candidate(), np.zeros(2))
    problem.nominal = _beam(1.04, 1.5)
    assert problem.simulations == 1
    second = problem.model_residuals(nominal_candidate(), np.zeros(2))
    assert problem.simulations == 2
    assert np.max(np.abs(second)) < 1e-3 < np.max(np.abs(first))


# -- finite differences and the final Jacobian ------------------------------------------------


def _curve(x):
    t = np.linspace(0.0, 1.0, 40)
    return x[0] * np.exp(-x[1] * t) + x[2] * t**2 - np.cos(3.0 * t)


@pytest.mark.parametrize(
    ('x', 'lo', 'hi'),
    [
        ([0.3, -1.2, 0.0], [-1.0, -2.0, -1.0], [1.0, 2.0, 1.0]),  # negative, zero, inside
        ([0.999, -1.9999, 2e-3], [-1.0, -2.0, 0.0], [1.0, 2.0, 1.0]),  # turned at a bound
        ([0.5, 1.0, 1e-9], [0.5 - 1e-7, 0.0, 0.0], [0.5 + 1e-7, 2.0, 1e-9]),  # pinched
    ],
)
def test_forward_differences_take_scipys_two_point_steps(x, lo, hi):
    from scipy.optimize._numdiff import approx_derivative

    x, lo, hi = (np.asarray(v, dtype=float) for v in (x, lo, hi))
    ours = forward_jacobian(_curve, x, _curve(x), lo, hi)
    scipys = approx_derivative(
        _curve, x, method='2-point', rel_step=DIFF_STEP, f0=_curve(x), bounds=(lo, hi)
    )
    np.testing.assert_array_equal(ours, scipys)


def test_a_strength_off_on_its_bound_gets_the_datas_slope_not_the_simulators_tolerance():
    # Quadratic drag hidden; its strength at 1e-9 (off, where a fit of a no-gain linear
    # step starts). The column from three simulations that start their sweeps warm from
    # different beams: a step relative to 1e-9 alone (2e-12) measures the sweeps'
    # tolerance, one relative to the floor (the starting strength) the slope.
    drag = next(c for c in effect_candidates(NOMINAL) if c.name == 'quadratic_drag')
    model = Model((drag,))
    problem = _problem(_record(_beam(quadratic_drag=0.5), noise=1.0))
    lo, hi = model.bounds()
    x = np.array([0.01, 0.05, 1e-9])
    columns = {}
    for name, floor in (('relative', None), ('floored', model.step_floor())):
        columns[name] = []
        for shift in (0.0, 0.02, -0.03):
            warm = WarmStart()
            problem.model_residuals(model, x + np.array([shift, shift, 0.0]), warm=warm)
            problem.nominal = problem.nominal  # forget the remembered residuals

            def fun(v, warm=warm):
                return problem.model_residuals(model, v, warm=warm)

            columns[name].append(forward_jacobian(fun, x, fun(x), lo, hi, floor)[:, 2])

    def spread(cols):
        return max(np.linalg.norm(c - cols[0]) for c in cols[1:]) / np.linalg.norm(cols[0])

    # The floored column is as exact as the simulations (their sweeps stop at 1e-11 rad).
    assert spread(columns['floored']) < 1e-4 < 1e-2 < spread(columns['relative'])
    np.testing.assert_array_equal(model.step_floor(), [0.0, 0.0, drag.start / drag.scale])


def test_the_fit_skips_the_jacobian_that_only_ends_it_and_lands_where_scipy_does():
    from scipy.optimize import least_squares

    problem = _problem(_record(_beam(1.03, 1.4)))
    ours = problem.fit(nominal_candidate(), np.zeros(2))
    evaluations = []

    def fun(x):
        evaluations.append(x)
        return problem.model_residuals(nominal_candidate(), x)

    lo, hi = nominal_candidate().bounds()
    scipys = least_squares(
        fun, np.zeros(2), bounds=(lo, hi), diff_step=DIFF_STEP, xtol=1e-4, ftol=1e-4
    )
    # The same iterates (to the solver's tolerance: ours start their sweeps warm), the
    # skipped Jacobian coming after the last: fewer simulations.
    np.testing.assert_allclose(ours.x, scipys.x, rtol=1e-8)
    assert ours.evaluations <= len(evaluations) - 2


def test_a_remembered_simulation_is_not_run_again():
    problem = _problem(_record(NOMINAL))
    model, x = nominal_candidate(), np.array([0.01, 0.1])
    residuals = problem.model_residuals(model, x, 2.0)
    trajectory = problem.trajectory(model, x, 2.0)
    assert problem.simulations == 1
    np.testing.assert_array_equal(problem.residuals(trajectory), residuals)
    assert problem.trajectory(model, x) is problem.trajectory(model, x)
    assert problem.simulations == 2
