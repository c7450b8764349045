"""Nonlinear least squares of a free decay: offset plus damped sinusoids.

The model, on ``tau = t - t0``::

    y = c + d tau + sum_m e^{-sigma_m tau} (a_m cos(omega_m tau) + b_m sin(omega_m tau))

with the drift ``d`` optional. It is the free response of a linear damped system from rest,
the situation right after the paper's load drop (section B.3.2); it uses every sample instead
of the two peaks of the log decrement (B.20), so its frequency and damping are much less
noisy, and it returns a covariance (:mod:`lumpbeam_ros.core.ident.covariance`).

The beam is not linear: at the drop's 4 cm amplitude its first mode runs about 5 ppm fast
and oscillates about a level some micrometres off the static equilibrium, both in proportion
to the squared amplitude, ``A^2 e^{-2 sigma_1 tau}``. Averaged over the window these biases
exceed the statistical error several times over. The ``nonlinear`` model adds the two
leading terms of a weakly nonlinear oscillator: a level shift ``e e^{-2 sigma_1 tau}`` and a
frequency shift ``q e^{-2 sigma_1 tau}`` (rad/s) in the first mode's phase,
``theta_1 = omega_1 tau + q (1 - e^{-2 sigma_1 tau}) / (2 sigma_1)``. Its ``omega_1`` and
``c`` are then the small-amplitude frequency and the true equilibrium.

Over a record the sweep is nearly a ramp of the phase, so ``q`` is nearly collinear with
``omega_1`` and fitting it costs the frequency most of its precision. A :class:`ShiftPrior`
brings in what the model knows instead, ``q = gamma omega_1 A_1^2`` with the beam's backbone
``gamma`` (:mod:`lumpbeam_ros.core.ident.backbone`), as one more observation weighed by its
stated uncertainty (a maximum a posteriori fit).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.covariance import Covariance, sandwich_covariance
from lumpbeam_ros.core.ident.mode_estimate import TWO_PI, ModeEstimate
from lumpbeam_ros.core.ident.optimize import least_squares

#: A mode's starting point: (damped frequency in Hz, damping ratio).
ModeGuess = tuple[float, float]


@dataclass(frozen=True)
class ShiftPrior:
    """What a model says of the first mode's frequency shift: ``q = gamma omega_1 A_1^2``.

    Attributes:
        relative_per_m2: ``gamma``, the backbone's relative shift per squared amplitude
            (:class:`~lumpbeam_ros.core.ident.backbone.Backbone`), 1/m^2.
        relative_std: The prediction's standard deviation as a fraction of it.
    """

    relative_per_m2: float
    relative_std: float

    def predicted(self, x: np.ndarray, first: int) -> float:
        """``gamma omega_1 A_1^2`` at parameters ``x`` whose first mode starts at ``first``."""
        a, b, _, w = x[first : first + 4]
        return float(self.relative_per_m2 * w * (a * a + b * b))

    def row(self, x: np.ndarray, first: int, weight: float) -> tuple[float, np.ndarray]:
        """The weighted observation ``weight (q - gamma omega_1 A_1^2)`` and its gradient."""
        a, b, _, w = x[first : first + 4]
        gamma = self.relative_per_m2
        gradient = np.zeros(x.size)
        gradient[first] = -2.0 * gamma * w * a
        gradient[first + 1] = -2.0 * gamma * w * b
        gradient[first + 3] = -gamma * (a * a + b * b)
        gradient[-1] = 1.0
        return weight * (float(x[-1]) - self.predicted(x, first)), weight * gradient

    def weight(self, x: np.ndarray, first: int, noise: float) -> float:
        """The observation's weight: the residual noise over the prior's standard deviation.

        The standard deviation is taken at ``x`` (the fit's start) and then held, so the
        objective does not move under the solver; a floor of 1e-12 of ``omega_1`` keeps a
        beam whose shift vanishes from an infinite weight.
        """
        w = abs(float(x[first + 3]))
        std = self.relative_std * max(abs(self.predicted(x, first)), 1e-12 * w)
        return noise / std if std > 0.0 else 0.0


@dataclass(frozen=True)
class DampedSinusoidParameters:
    """A fitted decay.

    Attributes:
        t0: Time origin of ``tau``, s.
        x: Parameter vector ``[c, (d), a_1, b_1, sigma_1, omega_1, a_2, ...]``.
        covariance: Its covariance (see :class:`~lumpbeam_ros.core.ident.covariance.Covariance`).
        n_modes: Number of damped modes.
        drift: Whether ``d`` is in ``x``.
        n_samples: Samples fitted.
        residual_rms: RMS of the residuals.
        nonlinear: Whether ``e`` and ``q`` (the amplitude-dependent level and frequency of
            the first mode) end ``x``.
        n_evaluations: Model evaluations the solver needed.
        shift_prior: The prior ``q`` was fitted with, if any (a refit keeps it).
    """

    t0: float
    x: np.ndarray
    covariance: Covariance
    n_modes: int
    drift: bool
    n_samples: int
    residual_rms: float
    nonlinear: bool = False
    n_evaluations: int = 0
    shift_prior: ShiftPrior | None = None

    @property
    def _first_mode_index(self) -> int:
        return 2 if self.drift else 1

    @property
    def offset(self) -> float:
        """c: the level the decay converges to (at ``tau = 0`` when drifting), m."""
        return float(self.x[0])

    @property
    def offset_std(self) -> float:
        """Standard deviation of :attr:`offset`."""
        return float(math.sqrt(self.covariance.matrix[0, 0]))

    @property
    def drift_rate(self) -> float:
        """d, m/s (0 when not fitted)."""
        return float(self.x[1]) if self.drift else 0.0

    def shifted(self, t0: float) -> DampedSinusoidParameters:
        """The same curve with its time origin moved to ``t0`` (the covariance is kept).

        Moving the origin by ``D`` scales each mode by ``e^{-sigma D}`` and turns its phase
        by ``theta(D)``; the sweep of the first mode shrinks by ``e^{-2 sigma D}``, since
        ``sweep(tau' + D) = sweep(D) + e^{-2 sigma D} sweep(tau')``.

        Args:
            t0: The new origin, s.

        Returns:
            Parameters describing the same curve on ``tau' = t - t0``.
        """
        shift = float(t0) - self.t0
        if shift == 0.0:
            return self
        x = self.x.copy()
        x[0] += self.drift_rate * shift
        for m in range(self.n_modes):
            k = self.mode_slice(m).start
            a, b, s, w = x[k : k + 4]
            phase = w * shift
            if m == 0 and self.nonlinear:
                square = math.exp(-2.0 * s * shift)
                phase += x[-1] * float(_sweep(s, np.array([shift]))[0])
                x[-2] *= square
                x[-1] *= square
            scale = math.exp(-s * shift)
            cos, sin = math.cos(phase), math.sin(phase)
            x[k] = scale * (a * cos + b * sin)
            x[k + 1] = scale * (b * cos - a * sin)
        return replace(self, t0=float(t0), x=x)

    def mode_slice(self, index: int) -> slice:
        """Where mode ``index`` (0-based) sits in :attr:`x`."""
        start = self._first_mode_index + 4 * index
        return slice(start, start + 4)

    def mode(self, index: int = 0) -> ModeEstimate:
        """The figures of one mode (0 is the first fitted, normally the beam's first mode)."""
        s = self.mode_slice(index)
        cos_amp, sin_amp, decay_rate, damped_omega = self.x[s]
        return ModeEstimate.from_parameters(
            cos_amp, sin_amp, decay_rate, damped_omega, self.covariance.matrix[s, s]
        )

    def predict(self, t: np.ndarray) -> np.ndarray:
        """Evaluates the fitted model at stamps ``t``."""
        tau = np.asarray(t, dtype=float) - self.t0
        return _Decay(tau, self.n_modes, self.drift, self.nonlinear).value(self.x)

    @property
    def frequency_shift_hz(self) -> float:
        """q / 2 pi: how much faster the first mode runs at ``tau = 0`` (0 when linear)."""
        return float(self.x[-1]) / TWO_PI if self.nonlinear else 0.0

    @property
    def level_shift_m(self) -> float:
        """e: how far the first mode's centre is off ``c`` at ``tau = 0`` (0 when linear)."""
        return float(self.x[-2]) if self.nonlinear else 0.0

    def offset_of(self, t: np.ndarray, y: np.ndarray) -> tuple[float, float]:
        """The offset of another signal that shares this decay's poles, with its std.

        With the decays and frequencies fixed the model is linear, so one least-squares
        solve gives the level, e.g. of the tip pitch, that the oscillation settles to.

        Args:
            t: Stamps, s.
            y: The other signal at ``t``.

        Returns:
            The offset and its correlation-robust standard deviation.
        """
        tau = np.asarray(t, dtype=float) - self.t0
        y = np.asarray(y, dtype=float)
        design = _Decay(tau, self.n_modes, self.drift, self.nonlinear).design(self.x)
        coef, *_ = np.linalg.lstsq(design, y, rcond=None)
        cov = sandwich_covariance(design, y - design @ coef)
        return float(coef[0]), float(math.sqrt(cov.matrix[0, 0]))


class _Decay:
    """The model, its Jacobian and its linear design on fixed stamps, sharing the basis.

    The solver asks for the residuals and then the Jacobian at the same point; the decays,
    cosines and sines (the costly part) are computed once for both.
    """

    def __init__(self, tau: np.ndarray, n_modes: int, drift: bool, nonlinear: bool = False):
        self.tau = tau
        self.n_modes = n_modes
        self.drift = drift
        self.nonlinear = nonlinear
        self.first = 2 if drift else 1
        self._x: np.ndarray | None = None
        self._basis: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        self._square = np.empty(0)
        self._sweep = np.empty(0)

    def _update(self, x: np.ndarray) -> None:
        if self._x is not None and np.array_equal(x, self._x):
            return
        self._x = x.copy()
        tau = self.tau
        self._basis = []
        for m in range(self.n_modes):
            s, w = x[self.first + 4 * m + 2 : self.first + 4 * m + 4]
            decay = np.exp(-s * tau)
            phase = w * tau
            if m == 0 and self.nonlinear:
                # e^{-2 sigma tau} is the squared envelope; the sweep is its integral.
                self._square = decay * decay
                self._sweep = _sweep(s, tau)
                phase = phase + x[-1] * self._sweep
            self._basis.append((decay, decay * np.cos(phase), decay * np.sin(phase)))

    def design(self, x: np.ndarray) -> np.ndarray:
        """The columns that enter linearly (``c, d, a_m, b_m, e``) at the poles of ``x``."""
        self._update(x)
        columns = [np.ones_like(self.tau)]
        if self.drift:
            columns.append(self.tau)
        for _, cos, sin in self._basis:
            columns += [cos, sin]
        if self.nonlinear:
            columns.append(self._square)
        return np.column_stack(columns)

    def value(self, x: np.ndarray) -> np.ndarray:
        """The model at parameters ``x``."""
        self._update(x)
        y = np.full(self.tau.shape, x[0])
        if self.drift:
            y += x[1] * self.tau
        for m, (_, cos, sin) in enumerate(self._basis):
            a, b = x[self.first + 4 * m : self.first + 4 * m + 2]
            y += a * cos + b * sin
        if self.nonlinear:
            y += x[-2] * self._square
        return y

    def jacobian(self, x: np.ndarray) -> np.ndarray:
        """d model / d x at parameters ``x``."""
        self._update(x)
        tau = self.tau
        jac = np.empty((tau.size, x.size))
        jac[:, 0] = 1.0
        if self.drift:
            jac[:, 1] = tau
        for m, (_, cos, sin) in enumerate(self._basis):
            k = self.first + 4 * m
            a, b = x[k : k + 2]
            in_phase = a * cos + b * sin
            quadrature = b * cos - a * sin  # d(mode)/d(phase)
            jac[:, k] = cos
            jac[:, k + 1] = sin
            jac[:, k + 2] = -tau * in_phase
            jac[:, k + 3] = tau * quadrature
            if m == 0 and self.nonlinear:
                s, e, q = x[k + 2], x[-2], x[-1]
                jac[:, k + 2] -= 2.0 * e * tau * self._square
                jac[:, k + 2] += q * _sweep_rate(s, tau, self._square, self._sweep) * quadrature
                jac[:, -2] = self._square
                jac[:, -1] = self._sweep * quadrature
        return jac


class _Problem:
    """What the solvers minimise: the data's residuals, and the prior's observation if any."""

    def __init__(
        self, decay: _Decay, y: np.ndarray, prior: ShiftPrior | None = None, weight: float = 0.0
    ):
        self.decay = decay
        self.y = y
        self.prior = prior
        self.weight = weight

    def residuals(self, x: np.ndarray) -> np.ndarray:
        """The model minus the data, then the prior's weighted observation."""
        residuals = np.asarray(self.decay.value(x) - self.y)
        if self.prior is None:
            return residuals
        return np.append(residuals, self.prior.row(x, self.decay.first, self.weight)[0])

    def jacobian(self, x: np.ndarray) -> np.ndarray:
        """d residuals / d x."""
        jacobian = self.decay.jacobian(x)
        rows = self.prior_rows(x)
        return jacobian if rows is None else np.vstack([jacobian, rows])

    def prior_rows(self, x: np.ndarray) -> np.ndarray | None:
        """The prior's weighted gradient as a one-row matrix (``None`` without a prior)."""
        if self.prior is None:
            return None
        return self.prior.row(x, self.decay.first, self.weight)[1][None, :]

    def solve(self, x0: np.ndarray, warm: bool) -> tuple[np.ndarray, int]:
        """The least-squares solution from ``x0`` and the evaluations it took.

        Gauss-Newton first when ``x0`` is next to the solution (``warm``), else (or when it
        fails) Levenberg-Marquardt (:func:`~.optimize.least_squares`).
        """
        solution = least_squares(self.residuals, self.jacobian, x0, warm, self.y.size)
        return solution.x, solution.n_evaluations


def _sweep(sigma: float, tau: np.ndarray) -> np.ndarray:
    """``(1 - e^{-2 sigma tau}) / (2 sigma)``: the phase a unit frequency shift adds."""
    if abs(sigma) * float(np.max(np.abs(tau), initial=0.0)) < 1e-8:
        return np.asarray(tau - sigma * tau * tau)
    return -np.expm1(-2.0 * sigma * tau) / (2.0 * sigma)


def _sweep_rate(
    sigma: float, tau: np.ndarray, square: np.ndarray, sweep: np.ndarray
) -> np.ndarray:
    """d sweep / d sigma = (tau e^{-2 sigma tau} - sweep) / sigma."""
    if abs(sigma) * float(np.max(np.abs(tau), initial=0.0)) < 1e-8:
        return np.asarray(-tau * tau)
    return np.asarray((tau * square - sweep) / sigma)


def _pole_vector(
    decays: Sequence[float], omegas: Sequence[float], drift: bool, nonlinear: bool
) -> np.ndarray:
    """A parameter vector with the given poles and zero amplitudes (and no sweep)."""
    x = [0.0] * (1 + int(drift))
    for s, w in zip(decays, omegas, strict=True):
        x += [0.0, 0.0, float(s), float(w)]
    if nonlinear:
        x += [0.0, 0.0]
    return np.asarray(x)


def _linear_amplitudes(
    tau: np.ndarray,
    y: np.ndarray,
    decays: Sequence[float],
    omegas: Sequence[float],
    drift: bool,
    nonlinear: bool = False,
) -> tuple[np.ndarray, np.ndarray]:
    """The best ``c, d, a_m, b_m, e`` for fixed poles (variable projection), and the fit."""
    design = _Decay(tau, len(decays), drift, nonlinear).design(
        _pole_vector(decays, omegas, drift, nonlinear)
    )
    coef, *_ = np.linalg.lstsq(design, y, rcond=None)
    return coef, design @ coef


def spectral_peak_hz(
    t: np.ndarray, y: np.ndarray, min_hz: float = 0.0, max_hz: float = math.inf
) -> float:
    """The strongest frequency of ``y`` in a band, from a zero-padded FFT.

    Uneven stamps are resampled linearly on their median step first.

    Args:
        t: Increasing stamps, s.
        y: Samples.
        min_hz: Lowest frequency considered.
        max_hz: Highest frequency considered.

    Returns:
        The peak frequency, refined by a parabola through the log magnitudes (NaN when the
        band holds no FFT bin).
    """
    dt = float(np.median(np.diff(t)))
    grid = np.arange(t[0], t[-1], dt)
    u = np.interp(grid, t, y)
    # No taper: a decay is strongest at the start, which a Hann window would suppress.
    u = u - u.mean()
    size = 1 << int(np.ceil(np.log2(4 * u.size)))
    mag = np.abs(np.fft.rfft(u, size))
    freqs = np.fft.rfftfreq(size, dt)
    band = np.flatnonzero((freqs >= max(min_hz, freqs[1])) & (freqs <= max_hz))
    if band.size == 0:
        return float('nan')
    k = int(band[np.argmax(mag[band])])
    if 0 < k < mag.size - 1:
        lo, mid, hi = np.log(mag[k - 1 : k + 2] + 1e-300)
        denom = lo - 2.0 * mid + hi
        shift = 0.5 * (lo - hi) / denom if denom < 0 else 0.0
        return float((k + shift) * (freqs[1] - freqs[0]))
    return float(freqs[k])


class DampedSinusoidFit:
    """Least-squares fit of offset + damped sinusoids, in a fit/predict shape.

    Example::

        params = DampedSinusoidFit(n_modes=1).fit(t, z)
        mode = params.mode(0)     # frequency, damping ratio, decrement with stds
        z_hat = params.predict(t)
        # A few samples later, started from the last solution (a live window):
        params = DampedSinusoidFit(n_modes=1).fit(t2, z2, start=params)

    Args:
        n_modes: Number of damped modes.
        drift: Also fit a linear drift.
        min_frequency_hz: Band for the automatic starting frequency.
        max_frequency_hz: Band for the automatic starting frequency.
        nonlinear: Also fit the first mode's amplitude-dependent level and frequency (see
            the module docstring).
        shift_prior: With ``nonlinear``, what the model predicts of the frequency shift.
    """

    def __init__(
        self,
        n_modes: int = 1,
        drift: bool = False,
        min_frequency_hz: float = 0.05,
        max_frequency_hz: float = math.inf,
        nonlinear: bool = False,
        shift_prior: ShiftPrior | None = None,
    ):
        if n_modes < 1:
            raise ValueError('n_modes must be at least 1')
        self.n_modes = n_modes
        self.drift = drift
        self.nonlinear = nonlinear
        self.shift_prior = shift_prior
        self.min_frequency_hz = min_frequency_hz
        self.max_frequency_hz = max_frequency_hz
        self.params_: DampedSinusoidParameters | None = None

    @classmethod
    def like(cls, params: DampedSinusoidParameters) -> DampedSinusoidFit:
        """A fit of the model ``params`` has: its modes, drift, nonlinear terms and prior."""
        return cls(
            n_modes=params.n_modes,
            drift=params.drift,
            nonlinear=params.nonlinear,
            shift_prior=params.shift_prior,
        )

    @property
    def n_params(self) -> int:
        """Length of the parameter vector."""
        return 1 + int(self.drift) + 4 * self.n_modes + 2 * int(self.nonlinear)

    def fit(
        self,
        t: np.ndarray,
        y: np.ndarray,
        initial: Sequence[ModeGuess] | None = None,
        t0: float | None = None,
        start: DampedSinusoidParameters | None = None,
    ) -> DampedSinusoidParameters:
        """Fits the model to samples.

        Args:
            t: Increasing stamps, s (gaps allowed).
            y: Samples, e.g. the tip z after a release, m.
            initial: A (damped frequency Hz, damping ratio) start per mode. Missing ones
                come from the spectrum of what the earlier modes leave.
            t0: Time origin of the decay (default ``t[0]``).
            start: A previous solution with the same modes and drift to start from (moved
                to ``t0``; a linear one may start a nonlinear fit and the reverse); it
                replaces ``initial``. A sliding window then converges in a step or two.

        Returns:
            The fitted parameters, also kept as ``self.params_``.

        Raises:
            LumpbeamError: Too few samples for the model, a ``start`` with other modes, or
                the fit did not converge to finite values.
        """
        t = np.asarray(t, dtype=float)
        y = np.asarray(y, dtype=float)
        n_params = self.n_params
        if t.size != y.size or t.size < 2 * n_params:
            raise LumpbeamError(f'damped-sinusoid fit: {t.size} samples for {n_params} parameters')
        origin = float(t[0] if t0 is None else t0)
        tau = t - origin
        if start is not None:
            if start.n_modes != self.n_modes or start.drift != self.drift:
                raise LumpbeamError('damped-sinusoid fit: the start has other modes or drift')
            x0 = start.shifted(origin).x
            # A linear solution starts a nonlinear fit with no level or frequency shift.
            if self.nonlinear and not start.nonlinear:
                x0 = np.concatenate([x0, [0.0, 0.0]])
            elif start.nonlinear and not self.nonlinear:
                x0 = x0[:-2]
        else:
            x0 = self._start(tau, y, list(initial or []))
        decay = _Decay(tau, self.n_modes, self.drift, self.nonlinear)
        problem = _Problem(decay, y)
        prior = self.shift_prior if self.nonlinear else None
        evaluations = 0
        # A trial step can give a mode a growing envelope that overflows to inf: both solvers
        # reject such a step (its residual is not smaller), and a non-finite solution is
        # refused below, so numpy's warnings would only alarm a reader of the node's log.
        with np.errstate(over='ignore', invalid='ignore'):
            warm = start is not None
            if prior is not None:
                # The prior is weighed against the residual noise: a previous window's, or
                # that of a fit without the prior, which then starts the one with it.
                if start is not None:
                    noise = start.residual_rms
                else:
                    x0, evaluations = problem.solve(x0, warm=False)
                    noise = float(np.sqrt(np.mean((decay.value(x0) - y) ** 2)))
                    warm = True
                weight = prior.weight(x0, decay.first, noise) if np.all(np.isfinite(x0)) else 0.0
                problem = _Problem(decay, y, prior, weight)
            x, used = problem.solve(x0, warm)
            evaluations += used
        if not np.all(np.isfinite(x)):
            raise LumpbeamError('damped-sinusoid fit did not converge')
        # A negative omega is the same mode with b (and the sweep) negated; keep it positive.
        for m in range(self.n_modes):
            k = 1 + int(self.drift) + 4 * m
            if x[k + 3] < 0.0:
                x[k + 1] = -x[k + 1]
                x[k + 3] = -x[k + 3]
                if m == 0 and self.nonlinear:
                    x[-1] = -x[-1]
        residuals = decay.value(x) - y
        cov = sandwich_covariance(decay.jacobian(x), residuals, problem.prior_rows(x))
        self.params_ = DampedSinusoidParameters(
            origin,
            x,
            cov,
            self.n_modes,
            self.drift,
            int(t.size),
            float(np.sqrt(np.mean(residuals**2))),
            self.nonlinear,
            evaluations,
            prior,
        )
        return self.params_

    def predict(self, t: np.ndarray) -> np.ndarray:
        """Evaluates the last fit at stamps ``t``.

        Raises:
            LumpbeamError: :meth:`fit` has not succeeded yet.
        """
        if self.params_ is None:
            raise LumpbeamError('damped-sinusoid fit: predict() before fit()')
        return self.params_.predict(t)

    def _start(self, tau: np.ndarray, y: np.ndarray, guesses: list[ModeGuess]) -> np.ndarray:
        """Starting parameters: the guessed poles with their best amplitudes."""
        decays: list[float] = []
        omegas: list[float] = []
        for m in range(self.n_modes):
            if m < len(guesses):
                f_d, zeta = guesses[m]
            else:
                f_d, zeta = self._next_guess(tau, y, decays, omegas)
            w = TWO_PI * f_d
            omegas.append(w)
            decays.append(zeta * w / math.sqrt(max(1.0 - zeta * zeta, 1e-12)))
        x0 = _pole_vector(decays, omegas, self.drift, self.nonlinear)
        coef, _ = _linear_amplitudes(tau, y, decays, omegas, self.drift, self.nonlinear)
        head = 1 + int(self.drift)
        x0[:head] = coef[:head]
        for m in range(self.n_modes):
            x0[head + 4 * m : head + 4 * m + 2] = coef[head + 2 * m : head + 2 * m + 2]
        if self.nonlinear:
            x0[-2] = coef[-1]
        return x0

    def _next_guess(
        self, tau: np.ndarray, y: np.ndarray, decays: list[float], omegas: list[float]
    ) -> ModeGuess:
        """A start for one more mode: the spectral peak of what earlier modes leave.

        Its decay comes from the amplitudes demodulated on the two halves of the record.
        """
        _, fitted = _linear_amplitudes(tau, y, decays, omegas, self.drift)
        rest = y - fitted
        low = self.min_frequency_hz
        if omegas:
            low = max(low, 1.2 * max(omegas) / TWO_PI)
        f_d = spectral_peak_hz(tau, rest, low, self.max_frequency_hz)
        if not math.isfinite(f_d):
            raise LumpbeamError('damped-sinusoid fit: no spectral peak in the frequency band')
        w = TWO_PI * f_d
        half = tau.size // 2
        amps = []
        for part in (slice(0, half), slice(half, None)):
            c, _ = _linear_amplitudes(tau[part], rest[part], [0.0], [w], False)
            amps.append(math.hypot(c[1], c[2]))
        span = float(np.mean(tau[half:]) - np.mean(tau[:half]))
        sigma = math.log(amps[0] / amps[1]) / span if min(amps) > 0 and span > 0 else 0.0
        sigma = max(sigma, 0.0)
        return f_d, sigma / math.hypot(sigma, w)
