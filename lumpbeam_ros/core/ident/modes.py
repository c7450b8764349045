"""Several modes of a free vibration, each kept only when it stands out of the noise.

A free vibration is a sum of damped modes (paper section B.3.2 fits one; a beam or an arm
rings in several). The number of modes is chosen by forward selection:

1. the decay is fitted with its strongest mode (:mod:`~lumpbeam_ros.core.ident.identify`);
2. the matrix pencil (:class:`~lumpbeam_ros.core.ident.pencil.MatrixPencil`) of what the fit
   leaves proposes the strongest remaining mode (frequency and damping);
3. the least-squares fit is rerun with that mode added, started from the last solution;
4. the new mode is kept only if its amplitude passes a Wald test against the noise:
   ``[a b] C^-1 [a b]^T > k^2``, ``(a, b)`` its cosine and sine amplitudes and ``C`` their
   correlation-robust covariance (:mod:`~lumpbeam_ros.core.ident.covariance`), with
   ``k = sqrt(2 ln(N / alpha))`` for ``N`` samples and false-alarm probability ``alpha``
   (``fit.mode_false_alarm``);
5. a harmonic of a stronger mode (:func:`harmonic_of`) stays in the fit but is not a mode.

Why this test and not an information criterion: under noise alone the statistic of one trial
frequency and decay is chi-square with 2 degrees of freedom, ``P(> k^2) = e^{-k^2/2}``;
searching about ``N`` independent frequencies and decay rates, the largest exceeds ``k^2``
with probability at most ``N e^{-k^2/2} = alpha`` (Bonferroni). The threshold thus says what
it guarantees (a spurious mode in one window of a thousand), uses the same robust covariance
as the reported standard deviations (correlated camera noise does not invent modes), and
grows only as ``sqrt(ln N)`` with the record, where BIC's penalty ``4 ln N`` on the residual
sum of squares assumes white noise and has no stated error rate.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.mode_estimate import TWO_PI, ModeEstimate
from lumpbeam_ros.core.ident.pencil import MatrixPencil
from lumpbeam_ros.core.ident.settings import IdentifierConfig
from lumpbeam_ros.core.ident.sinusoid import DampedSinusoidFit, DampedSinusoidParameters, ModeGuess

#: A mode must lie below this fraction of the Nyquist frequency (aliasing, the camera's
#: own response near Nyquist).
_NYQUIST_FRACTION = 0.9
#: Damping ratio above which a fitted "mode" is a transient of the noise, not a mode.
_MAX_DAMPING = 0.5
#: Two modes closer than this many frequency-resolution cells (1 / record length) are one.
_RESOLUTION_CELLS = 2.0
#: The harmonics of a mode that are fitted as such (:func:`harmonic_of`), and how close
#: their frequency (relative) and decay rate (relative to n times the mode's) must be.
_HARMONICS = (2, 3)
_HARMONIC_FREQUENCY_TOL = 0.01
_HARMONIC_DECAY_TOL = 0.3
#: Samples of what the fit leaves that the pencil sees at most (its cost is linear in them):
#: 5.7 s at 180 Hz, long enough to start a lightly damped mode, which the fit then refines.
_PENCIL_MAX_POINTS = 1024
#: A candidate whose fixed-pole statistic is below this fraction of the threshold is refused
#: without a refit: the refit frees its pole, which raises the statistic, but not twofold.
_SCREEN_FRACTION = 0.5


def harmonic_of(params: DampedSinusoidParameters, index: int) -> int | None:
    """The stronger mode whose harmonic the fitted mode ``index`` is, or ``None``.

    A large swing puts harmonics of a mode into the tip's motion (the tip's arc, a stiffening
    spring): at ``n`` times its frequency (n = 2, 3), decaying ``n`` times as fast (they go
    with the n-th power of its amplitude). The fit keeps them, so that they leave nothing
    behind for the next mode's search, but they are not modes of the structure.
    """
    return _harmonic_of([params.mode(m) for m in range(params.n_modes)], index)


def _harmonic_of(modes: list[ModeEstimate], index: int) -> int | None:
    mode = modes[index]
    for m, base in enumerate(modes):
        if m == index or not base.amplitude > mode.amplitude:
            continue
        for n in _HARMONICS:
            frequency_gap = abs(mode.damped_frequency_hz / (n * base.damped_frequency_hz) - 1.0)
            decay_gap = abs(mode.decay_rate - n * base.decay_rate)
            allowed = max(_HARMONIC_DECAY_TOL * n * base.decay_rate, 3.0 * mode.decay_rate_std)
            if frequency_gap < _HARMONIC_FREQUENCY_TOL and decay_gap <= allowed:
                return m
    return None


def structural_modes(params: DampedSinusoidParameters) -> list[int]:
    """The indices of the fitted modes that are not harmonics of another."""
    modes = [params.mode(m) for m in range(params.n_modes)]
    return [m for m in range(len(modes)) if _harmonic_of(modes, m) is None]


@dataclass(frozen=True)
class ModeChoice:
    """The modes kept and why the next one was not.

    Attributes:
        params: The fit with the modes kept.
        threshold: The k of the Wald test.
        refused: Why the search stopped: the refused mode's figures, or what was missing.
    """

    params: DampedSinusoidParameters
    threshold: float
    refused: str


def detection_threshold(n_samples: int, false_alarm: float) -> float:
    """k: how many standard deviations a further mode's amplitude must exceed.

    Args:
        n_samples: Samples fitted.
        false_alarm: Probability that noise alone passes (``fit.mode_false_alarm``).

    Returns:
        ``sqrt(2 ln(N / alpha))``.
    """
    return math.sqrt(2.0 * math.log(max(n_samples, 2) / false_alarm))


def mode_significance(params: DampedSinusoidParameters, index: int) -> float:
    """The Wald statistic ``sqrt([a b] C^-1 [a b]^T)`` of one fitted mode's amplitude.

    Args:
        params: A fit.
        index: The mode (0-based, in the fit's order).

    Returns:
        The amplitude in units of its standard deviation (0 when the covariance is singular).
    """
    part = params.mode_slice(index)
    ab = params.x[part][:2]
    cov = params.covariance.matrix[part, part][:2, :2]
    try:
        value = float(ab @ np.linalg.solve(cov, ab))
    except np.linalg.LinAlgError:
        return 0.0
    return math.sqrt(max(value, 0.0))


def choose_modes(
    t: np.ndarray, z: np.ndarray, params: DampedSinusoidParameters, config: IdentifierConfig
) -> ModeChoice:
    """Adds modes to a fitted decay while each new one passes the noise test.

    Args:
        t: Stamps of the fitted stretch, s.
        z: The samples fitted.
        params: The fit so far (at least the first mode).
        config: ``fit.max_modes``, ``fit.mode_false_alarm``, ``fit.min_frequency_hz``.

    Returns:
        The fit with the modes kept.
    """
    threshold = detection_threshold(t.size, config.mode_false_alarm)
    rate = 1.0 / float(np.median(np.diff(t)))
    band = (config.min_frequency_hz, _NYQUIST_FRACTION * 0.5 * rate)
    resolution = _RESOLUTION_CELLS / float(t[-1] - t[0])
    refused = ''
    while len(
        structural_modes(params)
    ) < config.max_modes and params.n_modes < config.max_modes + len(_HARMONICS):
        guess = _next_mode(t, z, params, band, resolution)
        if guess is None:
            refused = 'no further mode in the band'
            break
        screen, start = _screened(t, z, params, guess)
        if screen < _SCREEN_FRACTION * threshold:
            refused = (
                f'a mode at {guess[0]:.4g} Hz is {screen:.1f} sigma, below the noise threshold '
                f'{threshold:.1f}'
            )
            break
        try:
            trial = _refit(t, z, start)
        except LumpbeamError as exc:
            refused = f'the fit with a mode at {guess[0]:.4g} Hz failed ({exc})'
            break
        problem = _why_not(trial, band, resolution, threshold)
        if problem:
            refused = problem
            break
        params = trial
    return ModeChoice(params, threshold, refused)


def _fitted_frequencies(params: DampedSinusoidParameters) -> list[float]:
    """Damped frequencies of the fitted modes, Hz (from the parameters alone)."""
    return [float(params.x[params.mode_slice(m)][3]) / TWO_PI for m in range(params.n_modes)]


def _next_mode(
    t: np.ndarray,
    z: np.ndarray,
    params: DampedSinusoidParameters,
    band: tuple[float, float],
    resolution: float,
) -> ModeGuess | None:
    """The strongest damped mode of what the fit leaves, apart from the fitted ones."""
    rest = z - params.predict(t)
    head = slice(0, _PENCIL_MAX_POINTS)
    try:
        pencil = MatrixPencil(order=7).fit(t[head], rest[head])
    except LumpbeamError:
        return None
    fitted = _fitted_frequencies(params)
    for mode in pencil.modes:
        f = mode.damped_frequency_hz
        if not band[0] <= f <= band[1] or not 0.0 < mode.damping_ratio < _MAX_DAMPING:
            continue
        if any(abs(f - g) < resolution for g in fitted):
            continue
        return f, mode.damping_ratio
    return None


def _screened(
    t: np.ndarray, z: np.ndarray, params: DampedSinusoidParameters, guess: ModeGuess
) -> tuple[float, DampedSinusoidParameters]:
    """The guessed mode's amplitude in sigmas with its pole held, and the refit's start.

    With the pole fixed the mode is linear in ``(a, b)``: its statistic is
    ``sqrt(delta RSS / s^2)`` on what the fit leaves, one small solve instead of a fit, so a
    candidate far below the threshold costs no refit.
    """
    f_d, zeta = guess
    omega = TWO_PI * f_d
    sigma = zeta * omega / math.sqrt(max(1.0 - zeta * zeta, 1e-12))
    tau = t - params.t0
    rest = z - params.predict(t)
    decay = np.exp(-sigma * tau)
    design = np.column_stack([decay * np.cos(omega * tau), decay * np.sin(omega * tau)])
    ab, *_ = np.linalg.lstsq(design, rest, rcond=None)
    explained = design @ ab
    noise = float(rest @ rest) / max(t.size - params.x.size, 1)
    screen = math.sqrt(max(float(explained @ explained), 0.0) / max(noise, 1e-300))
    end = params.mode_slice(params.n_modes - 1).stop
    x = np.concatenate([params.x[:end], [ab[0], ab[1], sigma, omega], params.x[end:]])
    return screen, replace(params, x=x, n_modes=params.n_modes + 1)


def _refit(
    t: np.ndarray, z: np.ndarray, start: DampedSinusoidParameters
) -> DampedSinusoidParameters:
    """The least-squares fit from ``start`` (the last solution with the new mode added)."""
    return DampedSinusoidFit.like(start).fit(t, z, t0=start.t0, start=start)


def _why_not(
    trial: DampedSinusoidParameters,
    band: tuple[float, float],
    resolution: float,
    threshold: float,
) -> str:
    """Why the fit's last mode is not a mode of the data, or ``''``."""
    index = trial.n_modes - 1
    mode: ModeEstimate = trial.mode(index)
    f = mode.damped_frequency_hz
    where = f'a mode at {f:.4g} Hz'
    if not band[0] <= f <= band[1]:
        return f'{where} is outside {band[0]:.3g}..{band[1]:.3g} Hz'
    if not 0.0 < mode.damping_ratio < _MAX_DAMPING:
        return f'{where} has damping ratio {mode.damping_ratio:.3g}'
    if any(abs(f - g) < resolution for g in _fitted_frequencies(trial)[:index]):
        return f'{where} merges with a fitted mode'
    for m in range(index):
        if not trial.mode(m).decay_rate > 0.0:
            return f'{where} makes mode {m + 1} grow'
    significance = mode_significance(trial, index)
    if significance < threshold:
        return f'{where} is {significance:.1f} sigma, below the noise threshold {threshold:.1f}'
    return ''
