"""Nonlinear least squares of a free decay: offset plus damped sinusoids.

The model, on ``tau = t - t0``::

    y = c + d tau + sum_m e^{-sigma_m tau} (a_m cos(omega_m tau) + b_m sin(omega_m tau))

with the drift ``d`` optional. It is the free response of a linear damped system from rest,
the situation right after the paper's load drop (section B.3.2); it uses every sample instead
of the two peaks of the log decrement (B.20), so its frequency and damping are much less
noisy, and it returns a covariance (:mod:`lumpbeam_ros.ident.covariance`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from lumpbeam_ros.errors import LumpbeamError
from lumpbeam_ros.ident.covariance import Covariance, sandwich_covariance
from lumpbeam_ros.ident.modes import TWO_PI, ModeEstimate

#: A mode's starting point: (damped frequency in Hz, damping ratio).
ModeGuess = tuple[float, float]


@dataclass(frozen=True)
class DampedSinusoidParams:
    """A fitted decay.

    Attributes:
        t0: Time origin of ``tau``, s.
        x: Parameter vector ``[c, (d), a_1, b_1, sigma_1, omega_1, a_2, ...]``.
        covariance: Its covariance (see :class:`~lumpbeam_ros.ident.covariance.Covariance`).
        n_modes: Number of damped modes.
        drift: Whether ``d`` is in ``x``.
        n_samples: Samples fitted.
        residual_rms: RMS of the residuals.
    """

    t0: float
    x: np.ndarray
    covariance: Covariance
    n_modes: int
    drift: bool
    n_samples: int
    residual_rms: float

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

    def mode_slice(self, index: int) -> slice:
        """Where mode ``index`` (0-based) sits in :attr:`x`."""
        start = self._first_mode_index + 4 * index
        return slice(start, start + 4)

    def mode(self, index: int = 0) -> ModeEstimate:
        """The figures of one mode (0 is the first fitted, normally the beam's first mode)."""
        s = self.mode_slice(index)
        return ModeEstimate.from_parameters(*self.x[s], self.covariance.matrix[s, s])

    def predict(self, t: np.ndarray) -> np.ndarray:
        """Evaluates the fitted model at stamps ``t``."""
        return _model(self.x, np.asarray(t, dtype=float) - self.t0, self.n_modes, self.drift)

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
        decays = [self.x[self.mode_slice(m)][2] for m in range(self.n_modes)]
        omegas = [self.x[self.mode_slice(m)][3] for m in range(self.n_modes)]
        design = _design(tau, np.asarray(decays), np.asarray(omegas), self.drift)
        coef, *_ = np.linalg.lstsq(design, y, rcond=None)
        cov = sandwich_covariance(design, y - design @ coef)
        return float(coef[0]), float(math.sqrt(cov.matrix[0, 0]))


class _Decay:
    """The model and its Jacobian on fixed stamps, sharing the exponentials between them.

    The solver asks for the residuals and then the Jacobian at the same point; the decays,
    cosines and sines (the costly part) are computed once for both.
    """

    def __init__(self, tau: np.ndarray, n_modes: int, drift: bool):
        self.tau = tau
        self.n_modes = n_modes
        self.drift = drift
        self._x: np.ndarray | None = None
        self._basis: list[tuple[np.ndarray, np.ndarray]] = []

    def _update(self, x: np.ndarray) -> None:
        if self._x is not None and np.array_equal(x, self._x):
            return
        self._x = x.copy()
        first = 2 if self.drift else 1
        self._basis = []
        for m in range(self.n_modes):
            s, w = x[first + 4 * m + 2 : first + 4 * m + 4]
            decay = np.exp(-s * self.tau)
            phase = w * self.tau
            self._basis.append((decay * np.cos(phase), decay * np.sin(phase)))

    def value(self, x: np.ndarray) -> np.ndarray:
        """The model at parameters ``x``."""
        self._update(x)
        y = np.full(self.tau.shape, x[0])
        first = 1
        if self.drift:
            y += x[1] * self.tau
            first = 2
        for m, (cos, sin) in enumerate(self._basis):
            a, b = x[first + 4 * m : first + 4 * m + 2]
            y += a * cos + b * sin
        return y

    def jacobian(self, x: np.ndarray) -> np.ndarray:
        """d model / d x at parameters ``x``."""
        self._update(x)
        jac = np.empty((self.tau.size, x.size))
        jac[:, 0] = 1.0
        first = 1
        if self.drift:
            jac[:, 1] = self.tau
            first = 2
        for m, (cos, sin) in enumerate(self._basis):
            k = first + 4 * m
            a, b = x[k : k + 2]
            jac[:, k] = cos
            jac[:, k + 1] = sin
            jac[:, k + 2] = -self.tau * (a * cos + b * sin)
            jac[:, k + 3] = self.tau * (b * cos - a * sin)
        return jac


def _model(x: np.ndarray, tau: np.ndarray, n_modes: int, drift: bool) -> np.ndarray:
    return _Decay(tau, n_modes, drift).value(x)


def _design(tau: np.ndarray, decays: np.ndarray, omegas: np.ndarray, drift: bool) -> np.ndarray:
    """Columns of the model that is linear once decays and frequencies are fixed."""
    columns = [np.ones_like(tau)]
    if drift:
        columns.append(tau)
    for s, w in zip(decays, omegas, strict=True):
        decay = np.exp(-s * tau)
        columns += [decay * np.cos(w * tau), decay * np.sin(w * tau)]
    return np.column_stack(columns)


def _linear_amplitudes(
    tau: np.ndarray, y: np.ndarray, decays: np.ndarray, omegas: np.ndarray, drift: bool
) -> np.ndarray:
    """The best ``c, d, a_m, b_m`` for fixed decays and frequencies (variable projection)."""
    coef, *_ = np.linalg.lstsq(_design(tau, decays, omegas, drift), y, rcond=None)
    return coef


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

    Args:
        n_modes: Number of damped modes.
        drift: Also fit a linear drift.
        min_frequency_hz: Band for the automatic starting frequency.
        max_frequency_hz: Band for the automatic starting frequency.
    """

    def __init__(
        self,
        n_modes: int = 1,
        drift: bool = False,
        min_frequency_hz: float = 0.05,
        max_frequency_hz: float = math.inf,
    ):
        if n_modes < 1:
            raise ValueError('n_modes must be at least 1')
        self.n_modes = n_modes
        self.drift = drift
        self.min_frequency_hz = min_frequency_hz
        self.max_frequency_hz = max_frequency_hz
        self.params_: DampedSinusoidParams | None = None

    def fit(
        self,
        t: np.ndarray,
        y: np.ndarray,
        initial: Sequence[ModeGuess] | None = None,
        t0: float | None = None,
    ) -> DampedSinusoidParams:
        """Fits the model to samples.

        Args:
            t: Increasing stamps, s (gaps allowed).
            y: Samples, e.g. the tip z after a release, m.
            initial: A (damped frequency Hz, damping ratio) start per mode. Missing ones
                come from the spectrum of what the earlier modes leave.
            t0: Time origin of the decay (default ``t[0]``).

        Returns:
            The fitted parameters, also kept as ``self.params_``.

        Raises:
            LumpbeamError: Too few samples for the model, or the fit did not converge to
                finite values.
        """
        t = np.asarray(t, dtype=float)
        y = np.asarray(y, dtype=float)
        n_params = 1 + int(self.drift) + 4 * self.n_modes
        if t.size != y.size or t.size < 2 * n_params:
            raise LumpbeamError(f'damped-sinusoid fit: {t.size} samples for {n_params} parameters')
        origin = float(t[0] if t0 is None else t0)
        tau = t - origin
        guesses = list(initial or [])
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
        x0 = self._start(tau, y, np.asarray(decays), np.asarray(omegas))
        n_modes, drift = self.n_modes, self.drift
        decay = _Decay(tau, n_modes, drift)
        solution = least_squares(
            lambda x: decay.value(x) - y, x0, jac=decay.jacobian, method='lm', x_scale='jac'
        )
        x = solution.x
        if not np.all(np.isfinite(x)):
            raise LumpbeamError('damped-sinusoid fit did not converge')
        # A negative omega is the same mode with b negated; keep omega positive.
        for m in range(n_modes):
            k = 1 + int(drift) + 4 * m
            if x[k + 3] < 0.0:
                x[k + 1] = -x[k + 1]
                x[k + 3] = -x[k + 3]
        residuals = decay.value(x) - y
        cov = sandwich_covariance(decay.jacobian(x), residuals)
        self.params_ = DampedSinusoidParams(
            origin,
            x,
            cov,
            n_modes,
            drift,
            int(t.size),
            float(np.sqrt(np.mean(residuals**2))),
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

    def _start(
        self, tau: np.ndarray, y: np.ndarray, decays: np.ndarray, omegas: np.ndarray
    ) -> np.ndarray:
        coef = _linear_amplitudes(tau, y, decays, omegas, self.drift)
        head = 1 + int(self.drift)
        x0 = list(coef[:head])
        for m in range(self.n_modes):
            x0 += [coef[head + 2 * m], coef[head + 2 * m + 1], decays[m], omegas[m]]
        return np.asarray(x0)

    def _next_guess(
        self, tau: np.ndarray, y: np.ndarray, decays: list[float], omegas: list[float]
    ) -> ModeGuess:
        """A start for one more mode: the spectral peak of what earlier modes leave.

        Its decay comes from the amplitudes demodulated on the two halves of the record.
        """
        coef = _linear_amplitudes(tau, y, np.asarray(decays), np.asarray(omegas), self.drift)
        rest = y - _design_apply(tau, coef, decays, omegas, self.drift)
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
            c = _linear_amplitudes(tau[part], rest[part], np.zeros(1), np.array([w]), False)
            amps.append(math.hypot(c[1], c[2]))
        span = float(np.mean(tau[half:]) - np.mean(tau[:half]))
        sigma = math.log(amps[0] / amps[1]) / span if min(amps) > 0 and span > 0 else 0.0
        sigma = max(sigma, 0.0)
        return f_d, sigma / math.hypot(sigma, w)


def _design_apply(
    tau: np.ndarray, coef: np.ndarray, decays: list[float], omegas: list[float], drift: bool
) -> np.ndarray:
    return _design(tau, np.asarray(decays), np.asarray(omegas), drift) @ coef
