"""The measurement error, estimated from the data alone (no beam model needed).

Two parts. The white part comes from high-order differences (:func:`noise_std`). A camera
tracker's error is mostly not white: it depends on where the target sits in the image, so
it is smooth and follows the motion, and differences do not see it. Its slow part shows in
what a flexible description of the oscillation itself cannot explain: the residual of the
identifier's free-form damped-sinusoid fit of the free decay, with its amplitude-dependent
level and frequency (:func:`decay_error_std`). No beam model can do better than that fit on
sensor error, so the larger of the two is the floor a model's residual is judged against.
"""

from __future__ import annotations

import math

import numpy as np

from lumpbeam_ros.errors import LumpbeamError
from lumpbeam_ros.ident.sinusoid import DampedSinusoidFit

#: Order of the differences. The k-th difference damps a sinusoid by ``(2 sin(pi f / fs))^k``:
#: for the beam's 3 Hz at 180 Hz, 1e-4 at k = 4, so even a 20 mm swing leaves 2 um, while
#: white noise grows by ``sqrt(C(2k, k))``, a known factor.
DIFFERENCE_ORDER = 4

#: Parameters of the free-form decay fit (offset, amplitude pair, decay, frequency, the
#: nonlinear level and frequency terms): its residual is scaled by ``n / (n - p)``.
DECAY_FIT_PARAMETERS = 7


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
    nonlinear model, :class:`~lumpbeam_ros.ident.sinusoid.DampedSinusoidFit`) is fitted to
    the samples from ``start_s`` on; its residual RMS, corrected for the fitted parameters,
    is what the oscillation cannot explain.

    Args:
        t: Stamps, s.
        y: The signal (tip z or pitch).
        start_s: First sample fitted (after the higher modes have faded), s.
        t0: Time origin of the decay (the load event), s.

    Returns:
        The error standard deviation, or 0 when the fit fails (the white estimate then
        stands alone).
    """
    keep = np.asarray(t) >= start_s
    n = int(np.count_nonzero(keep))
    if n <= 4 * DECAY_FIT_PARAMETERS:
        return 0.0
    try:
        fit = DampedSinusoidFit(n_modes=1, nonlinear=True).fit(t[keep], y[keep], t0=t0)
    except LumpbeamError:
        return 0.0
    return float(fit.residual_rms * math.sqrt(n / (n - DECAY_FIT_PARAMETERS)))
