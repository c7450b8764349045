"""The solvers the identifier needs, in numpy: Gauss-Newton, Levenberg-Marquardt, bounded Brent.

They replace ``scipy.optimize.least_squares(method='lm', x_scale='jac')`` and
``scipy.optimize.minimize_scalar(method='bounded')`` on the path of ``lumpbeam analyze``:
importing ``scipy.optimize`` alone takes about 0.35 s, several times the analysis of a bag,
for two solvers of some sixty lines each. Both follow the published algorithms that scipy
wraps, so they reach the same solutions (the tests compare them with scipy).

References:
    J. J. Moré, "The Levenberg-Marquardt algorithm: implementation and theory", in
    Numerical Analysis, Lecture Notes in Mathematics 630, Springer, 1978, pp. 105-116.

    H. B. Nielsen, "Damping parameter in Marquardt's method", Technical Report
    IMM-REP-1999-05, Technical University of Denmark, 1999.

    R. P. Brent, "Algorithms for Minimization without Derivatives", Prentice-Hall, 1973,
    chapter 5 (the procedure ``localmin``; ``fmin`` in Forsythe, Malcolm and Moler, 1977).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

#: Nielsen's starting damping, relative to the largest scaled diagonal of J^T J. Small, for
#: a start near the solution (Madsen, Nielsen and Tingleff suggest 1e-6): the identifier
#: starts from spectral peaks or a previous fit, and MINPACK's first step, bounded by
#: ``100 ||D x0||``, is the Gauss-Newton step there too.
_INITIAL_DAMPING = 1e-6
#: The golden section's smaller fraction, (3 - sqrt 5) / 2.
_GOLDEN = 0.5 * (3.0 - math.sqrt(5.0))
#: sqrt of the double precision unit roundoff, Brent's relative resolution of x.
_SQRT_EPS = math.sqrt(2.2e-16)


@dataclass(frozen=True)
class LeastSquaresSolution:
    """Where :func:`levenberg_marquardt` stopped.

    Attributes:
        x: The solution.
        residuals: The residuals at ``x``.
        n_evaluations: Residual evaluations used (Jacobians are evaluated at accepted points
            only, where the residuals are already known).
        reason: ``'ftol'``, ``'xtol'``, ``'gtol'`` (converged) or ``'budget'`` (the
            evaluation budget ran out first).
    """

    x: np.ndarray
    residuals: np.ndarray
    n_evaluations: int
    reason: str

    @property
    def converged(self) -> bool:
        """Whether a tolerance, not the budget, ended the search."""
        return self.reason != 'budget'


def levenberg_marquardt(
    residuals: Callable[[np.ndarray], np.ndarray],
    jacobian: Callable[[np.ndarray], np.ndarray],
    x0: np.ndarray,
    ftol: float = 1e-8,
    xtol: float = 1e-8,
    gtol: float = 1e-8,
    max_evaluations: int | None = None,
) -> LeastSquaresSolution:
    """Minimises ``||residuals(x)||^2`` by Levenberg-Marquardt with Jacobian scaling.

    Each step ``p`` solves ``min ||J p + r||^2 + lambda ||D p||^2``, i.e. the linear least
    squares problem on the augmented system ``[J; sqrt(lambda) D] p = [-r; 0]`` (Moré's
    eq. 2.5). It is solved as such, not through the normal equations, whose squared
    condition number would cost half the digits: ``J = Q R`` once per Jacobian, and then each
    trial ``lambda`` needs only the small system ``[R; sqrt(lambda) D] p = [-Q^T r; 0]``.

    ``D`` scales each parameter by its Jacobian column norm, kept as a running maximum over
    the iterations (Moré section 6; MINPACK's ``mode = 1``, scipy's ``x_scale='jac'``), so
    the result does not depend on the parameters' units. ``lambda`` follows Nielsen: a step
    is taken when the gain ratio ``rho`` (actual over predicted reduction) is positive, and
    ``lambda`` then shrinks by ``max(1/3, 1 - (2 rho - 1)^3)``; a refused step multiplies
    it by ``nu``, which doubles with every refusal in a row.

    The tests are MINPACK's, with the same defaults as scipy: ``ftol`` on the relative
    actual and predicted reductions of the sum of squares, ``xtol`` on the scaled step
    relative to the scaled ``x``, ``gtol`` on the largest cosine between a Jacobian column
    and the residuals.

    Args:
        residuals: ``x -> r``, shape (m,). A trial point may return non-finite values: the
            step is then refused.
        jacobian: ``x -> dr/dx``, shape (m, n), called after ``residuals`` at the same ``x``.
        x0: Start, shape (n,).
        ftol: Relative reduction of the sum of squares below which the search stops.
        xtol: Relative scaled step below which the search stops.
        gtol: Scaled gradient below which the search stops.
        max_evaluations: Residual evaluations allowed (default ``100 n``, as scipy's
            ``'lm'`` with an analytic Jacobian).

    Returns:
        The solution, the evaluations used and why the search stopped.

    Raises:
        ValueError: The residuals at ``x0`` are not finite.
    """
    x = np.array(x0, dtype=float)
    budget = 100 * x.size if max_evaluations is None else max_evaluations
    r = np.asarray(residuals(x), dtype=float)
    evaluations = 1
    rss = _sum_of_squares(r)
    if not math.isfinite(rss):
        raise ValueError('the residuals at the starting point are not finite')
    scale = np.empty(0)
    damping = math.nan
    nu = 2.0
    while True:
        jac = np.asarray(jacobian(x), dtype=float)
        norms = np.linalg.norm(jac, axis=0)
        # MINPACK's diag: the first norms (1 for a zero column), then their running maximum.
        scale = np.maximum(scale, norms) if scale.size else np.where(norms > 0.0, norms, 1.0)
        if rss == 0.0 or _gradient_cosine(jac, r, norms, rss) <= gtol:
            return LeastSquaresSolution(x, r, evaluations, 'gtol')
        q, upper = np.linalg.qr(jac)
        qtr = q.T @ r
        if math.isnan(damping):
            damping = _INITIAL_DAMPING * float(np.max((norms / scale) ** 2))
        while True:
            if evaluations >= budget:
                return LeastSquaresSolution(x, r, evaluations, 'budget')
            augmented = np.vstack([upper, math.sqrt(damping) * np.diag(scale)])
            rhs = np.concatenate([-qtr, np.zeros(x.size)])
            step = np.linalg.lstsq(augmented, rhs, rcond=None)[0]
            trial = x + step
            trial_r = np.asarray(residuals(trial), dtype=float)
            evaluations += 1
            trial_rss = _sum_of_squares(trial_r)
            # ||r + J p||^2 = ||Q^T r + R p||^2 + (||r||^2 - ||Q^T r||^2).
            linear = qtr + upper @ step
            predicted = float(qtr @ qtr - linear @ linear)
            actual = rss - trial_rss
            gain = actual / predicted if predicted > 0.0 else -math.inf
            previous_rss = rss
            if gain > 0.0:
                x, r, rss = trial, trial_r, trial_rss
                damping *= max(1.0 / 3.0, 1.0 - (2.0 * gain - 1.0) ** 3)
                nu = 2.0
            else:
                # After some 600 good steps in a row the damping underflows to 0.
                damping = damping * nu if damping > 0.0 else _INITIAL_DAMPING
                nu *= 2.0
            if abs(actual) <= ftol * previous_rss and predicted <= ftol * previous_rss:
                if gain <= 2.0:
                    return LeastSquaresSolution(x, r, evaluations, 'ftol')
            step_norm = float(np.linalg.norm(scale * step))
            if step_norm <= xtol * (xtol + float(np.linalg.norm(scale * x))):
                return LeastSquaresSolution(x, r, evaluations, 'xtol')
            if gain > 0.0:
                break


def gauss_newton(
    residuals: Callable[[np.ndarray], np.ndarray],
    jacobian: Callable[[np.ndarray], np.ndarray],
    x0: np.ndarray,
    n_data: int,
    max_steps: int = 6,
) -> LeastSquaresSolution | None:
    """Plain Gauss-Newton from a start next to the solution (a live window's last fit).

    Near the minimum it converges quadratically, and a step costs one Jacobian and one
    small least-squares solve, without the trust-region bookkeeping of
    :func:`levenberg_marquardt`. It stops when the next step would lower the linearised
    residual sum of squares by less than a millionth of the noise variance (the sum of
    squares over ``n_data - n`` degrees of freedom): far less than the data can tell.

    Args:
        residuals: ``x -> r``, shape (m,).
        jacobian: ``x -> dr/dx``, shape (m, n).
        x0: Start, shape (n,).
        n_data: The data points among the residuals (a prior's rows aside).
        max_steps: Steps at most.

    Returns:
        The solution (``n_evaluations``: the steps taken, reason ``'ftol'``), or ``None``
        when a step does not lower the residuals or it does not converge.
    """
    x = x0
    residual = residuals(x)
    rss = _sum_of_squares(residual)
    tolerance = 1e-6 * rss / max(n_data - x.size, 1)
    for step in range(1, max_steps + 1):
        jac = jacobian(x)
        delta, *_ = np.linalg.lstsq(jac, -residual, rcond=None)
        linearised = residual + jac @ delta
        if rss - float(linearised @ linearised) < tolerance:
            return LeastSquaresSolution(x, residual, step, 'ftol')
        trial = x + delta
        trial_residual = residuals(trial)
        trial_rss = _sum_of_squares(trial_residual)
        if not trial_rss < rss:
            return None
        x, residual, rss = trial, trial_residual, trial_rss
    return None


def least_squares(
    residuals: Callable[[np.ndarray], np.ndarray],
    jacobian: Callable[[np.ndarray], np.ndarray],
    x0: np.ndarray,
    warm: bool,
    n_data: int,
) -> LeastSquaresSolution:
    """The least-squares solution from ``x0``: the one solver of the identification.

    :func:`gauss_newton` first when ``x0`` is next to the solution (``warm``), else (or when
    it fails) :func:`levenberg_marquardt`.

    Args:
        residuals: ``x -> r``, shape (m,).
        jacobian: ``x -> dr/dx``, shape (m, n).
        x0: Start, shape (n,).
        warm: Whether ``x0`` is a previous solution of nearly the same problem.
        n_data: The data points among the residuals (a prior's rows aside).

    Returns:
        The solution.

    Raises:
        ValueError: The residuals at ``x0`` are not finite.
    """
    found = gauss_newton(residuals, jacobian, x0, n_data) if warm else None
    return levenberg_marquardt(residuals, jacobian, x0) if found is None else found


def _sum_of_squares(r: np.ndarray) -> float:
    """``r @ r``, or infinity when it is not finite (a step that overflowed)."""
    with np.errstate(over='ignore', invalid='ignore'):
        total = float(r @ r)
    return total if math.isfinite(total) else math.inf


def _gradient_cosine(jac: np.ndarray, r: np.ndarray, norms: np.ndarray, rss: float) -> float:
    """MINPACK's ``gnorm``: the largest |cosine| between a Jacobian column and ``r``."""
    live = norms > 0.0
    if not np.any(live):
        return 0.0
    cosines = np.abs(jac[:, live].T @ r) / (norms[live] * math.sqrt(rss))
    return float(np.max(cosines))


@dataclass(frozen=True)
class ScalarMinimum:
    """Where :func:`bounded_scalar_minimum` stopped.

    Attributes:
        x: The minimiser found.
        fun: The function there.
        n_evaluations: Function evaluations used.
        converged: Whether the bracket shrank to the tolerance within the budget.
    """

    x: float
    fun: float
    n_evaluations: int
    converged: bool


def bounded_scalar_minimum(
    fun: Callable[[float], float],
    low: float,
    high: float,
    xatol: float = 1e-5,
    max_evaluations: int = 500,
) -> ScalarMinimum:
    """Brent's minimisation of a function of one variable on ``[low, high]``.

    Golden-section steps, replaced by a parabola through the three best points whenever it
    lands inside the bracket and moves less than half the step before last (Brent's
    ``localmin``, the algorithm of ``scipy.optimize.minimize_scalar(method='bounded')``,
    with the same tolerance: ``x`` is known to ``sqrt(eps) |x| + xatol / 3`` on each side).
    The function is never evaluated outside the bounds.

    Args:
        fun: The function.
        low: Lower bound.
        high: Upper bound (``>= low``).
        xatol: Absolute tolerance on the minimiser.
        max_evaluations: Evaluations allowed.

    Returns:
        The minimiser, its value and the evaluations used.

    Raises:
        ValueError: The bounds are not finite or out of order.
    """
    if not (math.isfinite(low) and math.isfinite(high)) or low > high:
        raise ValueError(f'bounds must be finite and ordered, got ({low}, {high})')
    a, b = low, high
    # x: best so far; w: second best; v: the previous w.
    x = w = v = a + _GOLDEN * (b - a)
    fx = fw = fv = fun(x)
    evaluations = 1
    step = previous = 0.0
    while True:
        middle = 0.5 * (a + b)
        tol1 = _SQRT_EPS * abs(x) + xatol / 3.0
        tol2 = 2.0 * tol1
        if abs(x - middle) <= tol2 - 0.5 * (b - a):
            return ScalarMinimum(x, fx, evaluations, True)
        if evaluations >= max_evaluations:
            return ScalarMinimum(x, fx, evaluations, False)
        golden = True
        if abs(previous) > tol1:
            # The parabola through (v, fv), (w, fw), (x, fx): its vertex is x + p / q.
            r = (x - w) * (fx - fv)
            q = (x - v) * (fx - fw)
            p = (x - v) * q - (x - w) * r
            q = 2.0 * (q - r)
            if q > 0.0:
                p = -p
            q = abs(q)
            before_last, previous = previous, step
            if abs(p) < abs(0.5 * q * before_last) and q * (a - x) < p < q * (b - x):
                golden = False
                step = p / q
                if (x + step - a) < tol2 or (b - x - step) < tol2:
                    step = tol1 if middle >= x else -tol1
        if golden:
            previous = (a - x) if x >= middle else (b - x)
            step = _GOLDEN * previous
        u = x + (step if abs(step) >= tol1 else math.copysign(tol1, step) if step else tol1)
        fu = fun(u)
        evaluations += 1
        if fu <= fx:
            if u >= x:
                a = x
            else:
                b = x
            v, fv, w, fw, x, fx = w, fw, x, fx, u, fu
        else:
            if u < x:
                a = u
            else:
                b = u
            if fu <= fw or w == x:
                v, fv, w, fw = w, fw, u, fu
            elif fu <= fv or v == x or v == w:
                v, fv = u, fu
