"""The numpy solvers against the scipy ones they replace, on the identifier's own problems."""

import math

import numpy as np
import pytest
from scipy.optimize import least_squares, minimize_scalar

from lumpbeam_ros.base.blas import single_threaded_blas
from lumpbeam_ros.core.ident import optimize
from lumpbeam_ros.core.ident.covariance import sandwich_covariance
from lumpbeam_ros.core.ident.onset import _residual
from lumpbeam_ros.core.ident.optimize import bounded_scalar_minimum, levenberg_marquardt
from lumpbeam_ros.core.ident.sinusoid import DampedSinusoidFit, _Decay

RATE_HZ = 180.0
TAU = np.arange(0.0, 10.0, 1.0 / RATE_HZ)


def _mode(f_hz, zeta, amp, phase):
    w = 2 * math.pi * f_hz * math.sqrt(1 - zeta**2)
    sigma = zeta * 2 * math.pi * f_hz
    return [amp * math.cos(phase), -amp * math.sin(phase), sigma, w]


# A drop's free decay as the identifier fits it: the first mode at 4 cm (with its
# amplitude-dependent level and frequency when nonlinear), a second mode at 21 Hz.
PROBLEMS = {
    'one mode': (1, False, False, [-0.05, *_mode(3.1, 0.01, 0.04, 0.3)]),
    'one mode, drift': (1, True, False, [-0.05, 2e-5, *_mode(3.1, 0.01, 0.04, 0.3)]),
    'one mode, nonlinear': (1, False, True, [-0.05, *_mode(3.1, 0.01, 0.04, 0.3), 8e-6, 0.1]),
    'two modes': (
        2,
        False,
        False,
        [-0.05, *_mode(3.1, 0.01, 0.04, 0.3), *_mode(21, 0.02, 1e-3, 1)],
    ),
    'two modes, nonlinear': (
        2,
        False,
        True,
        [-0.05, *_mode(3.1, 0.01, 0.04, 0.3), *_mode(21, 0.02, 1e-3, 1), 8e-6, 0.1],
    ),
}


@pytest.mark.parametrize('noise', [20e-6, 200e-6, 1e-3], ids=['20um', '200um', '1mm'])
@pytest.mark.parametrize('name', list(PROBLEMS))
def test_levenberg_marquardt_reaches_scipys_solution_far_below_the_std(name, noise):
    n_modes, drift, nonlinear, truth = PROBLEMS[name]
    decay = _Decay(TAU, n_modes, drift, nonlinear)
    rng = np.random.default_rng(int(noise * 1e6) + len(name))
    y = decay.value(np.asarray(truth)) + rng.normal(0.0, noise, TAU.size)
    # The cold fit's start: spectral peaks and the best amplitudes for them.
    fit = DampedSinusoidFit(n_modes, drift, nonlinear=nonlinear, min_frequency_hz=1.0)
    x0 = fit._start(TAU, y, [])

    def residuals(x):
        return decay.value(x) - y

    # As the identifier runs them: one BLAS thread, overflowing trial steps silent.
    with single_threaded_blas(), np.errstate(over='ignore', invalid='ignore'):
        ours = levenberg_marquardt(residuals, decay.jacobian, x0)
        theirs = least_squares(residuals, x0, jac=decay.jacobian, method='lm', x_scale='jac')
    assert ours.converged and theirs.success
    std = np.sqrt(np.diag(sandwich_covariance(decay.jacobian(ours.x), ours.residuals).matrix))
    # Both stop once the sum of squares (N sigma^2) falls by less than ftol = 1e-8 of itself,
    # which leaves x free by up to sqrt(ftol N) standard deviations (4e-3 here); on every
    # problem but one flat one they agree a thousand times closer.
    assert np.max(np.abs(ours.x - theirs.x) / std) < math.sqrt(1e-8 * TAU.size)
    rss, scipy_rss = ours.residuals @ ours.residuals, 2 * theirs.cost
    assert rss <= scipy_rss * (1 + 1e-9)
    assert ours.n_evaluations <= 2 * theirs.nfev + 5


def test_steps_that_overflow_are_refused_and_the_search_goes_on():
    # From x = -10 the Gauss-Newton step of exp(x) - 1 is e^10: its residual overflows.
    def residuals(x):
        return np.exp(x) - 1.0

    def jacobian(x):
        return np.exp(x)[:, None]

    with np.errstate(over='ignore', invalid='ignore'):
        ours = levenberg_marquardt(residuals, jacobian, np.array([-10.0]))
        theirs = least_squares(residuals, [-10.0], jac=jacobian, method='lm', x_scale='jac')
    assert ours.converged and abs(ours.x[0]) < 1e-8
    assert abs(ours.x[0] - theirs.x[0]) < 1e-8


def test_the_budget_and_a_bad_start_are_reported():
    t = np.linspace(0.0, 1.0, 30)

    def residuals(x):
        return np.exp(x[0] * t) - np.exp(-2.0 * t)

    def jacobian(x):
        return (t * np.exp(x[0] * t))[:, None]

    stopped = levenberg_marquardt(residuals, jacobian, np.array([3.0]), max_evaluations=2)
    assert (stopped.reason, stopped.n_evaluations, stopped.converged) == ('budget', 2, False)
    assert levenberg_marquardt(residuals, jacobian, np.array([-2.0])).reason == 'gtol'
    with pytest.raises(ValueError, match='starting point'):
        levenberg_marquardt(lambda x: np.full(3, np.nan), jacobian, np.array([0.0]))


def _onset_cost():
    """The onset fit's cost: the residual of a quartic start, near the release instant."""
    t = np.arange(-0.2, 0.3, 1.0 / RATE_HZ)
    tau = np.clip(t - 0.0021, 0.0, None)
    z = -0.05 + 3.0 * tau**2 - 20.0 * tau**3 + np.random.default_rng(2).normal(0, 2e-5, t.size)
    return lambda s: _residual(t, z, s)


SCALAR_PROBLEMS = {
    'parabola': (lambda x: (x - 0.3) ** 2, (-1.0, 2.0), 1e-5),
    'cosine': (math.cos, (2.0, 5.0), 1e-9),
    'at the bound': (lambda x: x, (1.0, 2.0), 1e-5),
    'flat': (lambda x: 1.0, (0.0, 1.0), 1e-5),
    'onset': (_onset_cost(), (-3.0 / RATE_HZ, 1.0 / RATE_HZ), 1e-3 / 60.0 / RATE_HZ),
}


@pytest.mark.parametrize('name', list(SCALAR_PROBLEMS))
def test_bounded_scalar_minimum_matches_scipys_bounded_brent(name):
    fun, bounds, xatol = SCALAR_PROBLEMS[name]
    ours = bounded_scalar_minimum(fun, *bounds, xatol=xatol)
    theirs = minimize_scalar(fun, bounds=bounds, method='bounded', options={'xatol': xatol})
    assert abs(ours.x - theirs.x) <= xatol
    assert ours.fun <= theirs.fun + 1e-15 * abs(theirs.fun)
    assert ours.converged
    assert ours.n_evaluations == theirs.nfev


def test_bounded_scalar_minimum_refuses_bad_bounds_and_reports_its_budget():
    with pytest.raises(ValueError, match='finite and ordered'):
        bounded_scalar_minimum(math.cos, 2.0, 1.0)
    with pytest.raises(ValueError, match='finite and ordered'):
        bounded_scalar_minimum(math.cos, 0.0, math.inf)
    short = bounded_scalar_minimum(math.cos, 2.0, 5.0, xatol=1e-12, max_evaluations=4)
    assert (short.n_evaluations, short.converged) == (4, False)


def _exponential(t, y):
    def residuals(x):
        return x[0] * np.exp(-x[1] * t) - y

    def jacobian(x):
        e = np.exp(-x[1] * t)
        return np.column_stack([e, -x[0] * t * e])

    return residuals, jacobian


def test_gauss_newton_from_a_warm_start_reaches_the_solution_in_few_steps():
    t = np.linspace(0.0, 2.0, 50)
    y = 2.0 * np.exp(-1.3 * t) + np.random.default_rng(1).normal(0.0, 1e-3, t.size)
    residuals, jacobian = _exponential(t, y)
    cold = levenberg_marquardt(residuals, jacobian, np.array([1.0, 1.0]))
    warm = optimize.gauss_newton(residuals, jacobian, cold.x + [1e-3, -1e-3], t.size)
    assert warm is not None and warm.n_evaluations <= 3
    np.testing.assert_allclose(warm.x, cold.x, rtol=1e-6)


def test_least_squares_falls_back_when_the_warm_start_is_not_near():
    t = np.linspace(0.0, 2.0, 50)
    residuals, jacobian = _exponential(t, 2.0 * np.exp(-1.3 * t))
    far = np.array([0.01, 9.0])  # Gauss-Newton's full step overshoots from here
    with np.errstate(over='ignore'):  # the trial's exponential; the solver refuses it
        assert optimize.gauss_newton(residuals, jacobian, far, t.size) is None
        solution = optimize.least_squares(residuals, jacobian, far, warm=True, n_data=t.size)
        cold = optimize.least_squares(residuals, jacobian, far, warm=False, n_data=t.size)
    np.testing.assert_allclose(solution.x, [2.0, 1.3], rtol=1e-6)
    np.testing.assert_array_equal(cold.x, solution.x)
