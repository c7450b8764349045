"""The paper's logarithmic decrement (B.20, B.21), from the peaks of a free decay.

It is the estimator of section B.3.2, kept for comparison with the paper: it uses two peak
amplitudes only, so it is far noisier than the least-squares fit of
:mod:`lumpbeam_ros.core.ident.sinusoid`, and biased by any offset error.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.mode_estimate import TWO_PI, damping_ratio_from_decrement
from lumpbeam_ros.core.ident.peaks import lobe_peaks, vertices


@dataclass(frozen=True)
class LogDecrementResult:
    """The decrement and what it implies.

    Attributes:
        log_decrement: delta = (1/n) ln(A_1 / A_{1+n}) (B.20).
        damping_ratio: zeta by B.21.
        damped_frequency_hz: n / (time of peak 1+n - time of peak 1), from a line through all
            peak times.
        periods: n, the number of periods between the two peaks used.
        peak_times: Times of the positive peaks found, s.
        peak_amplitudes: Their heights above the offset.
        offset: The level the peaks are measured from.
        noise_std: Sample noise seen around the peaks.
    """

    log_decrement: float
    log_decrement_std: float
    damping_ratio: float
    damping_ratio_std: float
    damped_frequency_hz: float
    damped_frequency_hz_std: float
    periods: int
    peak_times: np.ndarray
    peak_amplitudes: np.ndarray
    offset: float
    noise_std: float

    def envelope(self, t: np.ndarray) -> np.ndarray:
        """The decaying amplitude the decrement implies, through the first peak."""
        decay = self.log_decrement * self.damped_frequency_hz
        return np.asarray(
            self.peak_amplitudes[0] * np.exp(-decay * (np.asarray(t) - self.peak_times[0]))
        )


class LogDecrement:
    """Log-decrement estimator (B.20, B.21), in a fit/predict shape.

    Positive lobes are found with a hysteresis of ``hysteresis`` noise sigmas, so noise near
    the offset does not split a lobe; each peak is the vertex of a parabola fitted to the
    samples within a tenth of a period of the highest one (:mod:`~lumpbeam_ros.core.ident.peaks`).
    ``A_1`` is the first peak and ``A_{1+n}`` the last one above ``min_snr`` noise sigmas.

    Args:
        min_snr: Smallest peak height, in noise sigmas, that may serve as ``A_{1+n}``.
        hysteresis: Lobe threshold, in noise sigmas.
    """

    def __init__(self, min_snr: float = 20.0, hysteresis: float = 4.0):
        self.min_snr = min_snr
        self.hysteresis = hysteresis
        self.result_: LogDecrementResult | None = None

    def fit(
        self,
        t: np.ndarray,
        y: np.ndarray,
        offset: float | None = None,
        noise_std: float | None = None,
    ) -> LogDecrementResult:
        """Measures the decrement of a free decay.

        Args:
            t: Increasing stamps, s.
            y: Samples of the decay.
            offset: The level it decays to (default: the mean of ``y``).
            noise_std: Sample noise (default: estimated from third differences).

        Returns:
            The result, also kept as ``self.result_``.

        Raises:
            LumpbeamError: Fewer than two peaks stand above the noise.
        """
        t = np.asarray(t, dtype=float)
        y = np.asarray(y, dtype=float)
        level = float(np.mean(y)) if offset is None else float(offset)
        s = y - level
        sigma = difference_noise_std(y) if noise_std is None else float(noise_std)
        threshold = self.hysteresis * sigma
        if np.count_nonzero(np.abs(s) > threshold) < 4:
            raise LumpbeamError('log decrement: no oscillation above the noise')
        peaks = lobe_peaks(s, threshold, 'positive')
        if peaks.size < 2:
            raise LumpbeamError('log decrement: fewer than two peaks above the noise')
        peak_t, peak_a = vertices(t, s, peaks)
        usable = np.flatnonzero(peak_a > self.min_snr * sigma)
        if usable.size < 2:
            usable = np.arange(min(2, peak_t.size))
        last = int(usable[-1])
        # Periods between the peaks, robust to a lobe lost in the noise.
        n = max(1, round((peak_t[last] - peak_t[0]) / float(np.median(np.diff(peak_t)))))
        a1, an = peak_a[0], peak_a[last]
        if a1 <= 0.0 or an <= 0.0:
            raise LumpbeamError('log decrement: peaks do not stand above the offset')
        delta = math.log(a1 / an) / n
        # A peak from a parabola over a few samples has about the sample noise.
        delta_std = sigma * math.hypot(1.0 / a1, 1.0 / an) / n
        zeta = damping_ratio_from_decrement(delta)
        dzeta = (TWO_PI**2 / delta**3) * zeta**3 if delta > 0 else float('nan')
        period, period_std = _period(peak_t[: last + 1])
        result = LogDecrementResult(
            log_decrement=delta,
            log_decrement_std=delta_std,
            damping_ratio=zeta,
            damping_ratio_std=abs(dzeta) * delta_std,
            damped_frequency_hz=1.0 / period,
            damped_frequency_hz_std=period_std / period**2,
            periods=n,
            peak_times=peak_t,
            peak_amplitudes=peak_a,
            offset=level,
            noise_std=sigma,
        )
        self.result_ = result
        return result

    def predict(self, t: np.ndarray) -> np.ndarray:
        """The envelope the decrement implies at stamps ``t``.

        Raises:
            LumpbeamError: :meth:`fit` has not succeeded yet.
        """
        if self.result_ is None:
            raise LumpbeamError('log decrement: predict() before fit()')
        return self.result_.envelope(t)


def difference_noise_std(y: np.ndarray) -> float:
    """White-noise sigma from the median absolute third difference (var = 20 sigma^2).

    Third differences suppress a slow oscillation by ``(omega dt)^3`` (1e-3 for 3 Hz at
    180 Hz), so they see mostly the noise.
    """
    d3 = np.diff(y, 3)
    if d3.size == 0:
        return 0.0
    return float(1.4826 * np.median(np.abs(d3 - np.median(d3))) / math.sqrt(20.0))


def _period(peak_times: np.ndarray) -> tuple[float, float]:
    """The damped period as the slope of peak time against peak index, with its std."""
    n = peak_times.size
    if n == 2:
        return float(peak_times[1] - peak_times[0]), float('nan')
    index = np.arange(n, dtype=float)
    (slope, intercept), cov = np.polyfit(index, peak_times, 1, cov='unscaled')
    residuals = peak_times - (slope * index + intercept)
    s2 = float(residuals @ residuals) / (n - 2)
    return float(slope), float(math.sqrt(s2 * cov[0, 0]))
