"""The measurement error, estimated from the data alone (no beam model needed).

Two parts. The white part comes from high-order differences (:func:`noise_std`). A camera
tracker's error is mostly not white: it depends on where the target sits in the image, so
it is smooth and follows the motion, and differences do not see it. Its slow part shows in
what a flexible description of the oscillation itself cannot explain (:func:`decay_error_std`):
the identifier's free-form damped-sinusoid fit of the free decay, with its amplitude-dependent
level and frequency, gives the carrier, and its amplitude and phase may then wander slowly
(piecewise linear over ``KNOT_S``), so a dry-friction or drag envelope and a drifting
frequency are still "the oscillation", while an additive error away from the beam's
frequency is left over. No beam model can do better than that fit on
sensor error, so the larger of the two is the floor a model's residual is judged against.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.sinusoid import DampedSinusoidFit, DampedSinusoidParameters

#: Order of the differences. The k-th difference damps a sinusoid by ``(2 sin(pi f / fs))^k``:
#: for the beam's 3 Hz at 180 Hz, 1e-4 at k = 4, so even a 20 mm swing leaves 2 um, while
#: white noise grows by ``sqrt(C(2k, k))``, a known factor.
DIFFERENCE_ORDER = 4

#: Knot spacing of the slowly varying amplitude, s: three periods of the 3 Hz mode, so only
#: error within about 0.5 Hz of the beam's frequency is taken for oscillation.
KNOT_S = 1.0


def noise_std(y: np.ndarray, order: int = DIFFERENCE_ORDER) -> float:
    """White-noise sigma from the median absolute ``order``-th difference.

    The median ignores the few differences that straddle a load drop, where the signal
    has a kink.

    Args:
        y: Evenly sampled signal.
        order: Difference order.

    Returns:
        The noise standard deviation (0 for a signal too short to tell).
    """
    d = np.diff(np.asarray(y, dtype=float), order)
    if d.size < 8:
        return 0.0
    mad = float(np.median(np.abs(d - np.median(d))))
    return 1.4826 * mad / math.sqrt(math.comb(2 * order, order))


def decay_error_std(t: np.ndarray, y: np.ndarray, start_s: float, t0: float) -> float:
    """The sensor error, slow part included, from a free-form fit of a free decay.

    One damped mode with its amplitude-dependent level and frequency (the identifier's
    nonlinear model, :class:`~lumpbeam_ros.core.ident.sinusoid.DampedSinusoidFit`) is fitted to
    the samples from ``start_s`` on; then its amplitude and phase are freed piecewise
    linearly (a linear solve). The residual RMS, corrected for the fitted parameters, is
    what the oscillation cannot explain.

    Args:
        t: Stamps, s.
        y: The signal (tip z or pitch).
        start_s: First sample fitted (after the higher modes have faded), s.
        t0: Time origin of the decay (the load event), s.

    Returns:
        The error standard deviation, or 0 when the fit fails (the white estimate then
        stands alone).
    """
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    keep = t >= start_s
    n = int(np.count_nonzero(keep))
    t, y = t[keep], y[keep]
    try:
        fit = DampedSinusoidFit(n_modes=1, nonlinear=True).fit(t, y, t0=t0)
    except LumpbeamError:
        return 0.0
    design = _modulated_design(fit, t)
    if n <= 2 * design.shape[1]:
        return 0.0
    coef, *_ = np.linalg.lstsq(design, y, rcond=None)
    residual = y - design @ coef
    return float(np.sqrt(residual @ residual / (n - design.shape[1])))


def _modulated_design(fit: DampedSinusoidParameters, t: np.ndarray) -> np.ndarray:
    """The free-form decay's columns: offset, level shift, carrier times hat functions.

    The carrier's two quadratures (the fitted decay, frequency and its amplitude-dependent
    shift) times hat functions on ``KNOT_S`` knots give a piecewise-linear amplitude and
    phase.
    """

    def curve(**values: float) -> np.ndarray:
        x = np.zeros_like(fit.x)
        a = fit.mode_slice(0).start
        x[a + 2 : a + 4] = fit.x[a + 2 : a + 4]  # decay and frequency
        x[-1] = fit.x[-1]  # the amplitude-dependent frequency
        for index, value in values.items():
            x[{'a': a, 'b': a + 1, 'e': -2}[index]] = value
        return replace(fit, x=x).predict(t)

    cos, sin = curve(a=1.0), curve(b=1.0)
    knots = np.linspace(t[0], t[-1], max(2, int(np.ceil((t[-1] - t[0]) / KNOT_S)) + 1))
    columns = [np.ones_like(t), curve(e=1.0)]
    for k in range(knots.size):
        hat = np.interp(t, knots, np.eye(knots.size)[k])
        columns += [hat * cos, hat * sin]
    return np.column_stack(columns)
