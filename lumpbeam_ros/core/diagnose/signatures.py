"""Residual signatures: the fingerprints by which each missing effect shows in a drop test.

- Envelope shape of the free decay: viscous damping decays exponentially, dry friction
  linearly (a fixed loss per cycle), quadratic drag faster at large amplitude.
- Frequency drift with amplitude: a nonlinear spring changes the frequency as the swing
  decays; the library's effects do not (measured drift minus the model's own).
- Time shift against the load event: a late sensor shows the drop late.
- Slope-to-displacement ratio of the tip (pitch per z): a compliant mount concentrates the
  rotation at the root, which lowers the ratio from ~1.5/L (a bent cantilever) toward 1/L
  (a rigid rotation), while a uniformly softer beam keeps it.
- Static offsets before and after the event: an added mass sags the beam at rest.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.diagnose.gap import SETTLE_S, decay_mode
from lumpbeam_ros.core.diagnose.measurement import Record
from lumpbeam_ros.core.ident.logdec import difference_noise_std
from lumpbeam_ros.core.ident.peaks import lobe_peaks, vertices
from lumpbeam_ros.core.model.trajectory import TipTrajectory

#: Largest time shift searched against the load event, s.
MAX_SHIFT_S = 0.1

#: Half width of the band about the level a lobe of the swing must leave, in noise sigmas
#: (as the log decrement's).
PEAK_HYSTERESIS = 4.0


@dataclass(frozen=True)
class Signatures:
    """The signatures of one record against one model (the nominal model).

    Attributes:
        envelope: ``'exponential'``, ``'linear'`` or ``'amplitude_dependent'``: the decay law
            of the measured peaks (:func:`envelope_law`).
        envelope_terms: The dry and quadratic decay terms and their F statistics.
        frequency_drift: Relative change of the measured frequency from the first to the
            second half of the decay, minus the model's own change.
        time_shift_s: How late the measurement is against the model around the event, s.
        slope_ratio_error: Measured pitch-per-z regression slope over the model's, minus 1.
        static_offset_before_m: Mean z residual (model minus measurement) before the event.
        static_offset_after_m: The same over the last fifth of the record.
    """

    envelope: str
    envelope_terms: dict[str, float]
    frequency_drift: float
    time_shift_s: float
    slope_ratio_error: float
    static_offset_before_m: float
    static_offset_after_m: float

    def as_dict(self) -> dict[str, object]:
        """The JSON form."""
        return asdict(self)


#: F statistic above which an extra decay term is real (one extra parameter; p ~ 0.003).
ENVELOPE_F = 10.0


def envelope_terms(t: np.ndarray, amplitude: np.ndarray) -> dict[str, float]:
    """Which decay law the peak amplitudes follow, beyond the viscous one.

    The decay rate ``-dA/dt`` (central differences over one period) is regressed on the
    amplitude three ways: ``a A`` (viscous: exponential envelope), ``a A + b`` (plus dry
    friction: a constant loss, a linear envelope) and ``a A + c A^2`` (plus quadratic drag:
    amplitude-dependent). An extra term counts when it has its physical sign (b, c > 0) and
    its F statistic against the viscous law is large.

    Args:
        t: Peak times, s (both signs of the swing, so half a period apart).
        amplitude: Peak amplitudes, m.

    Returns:
        ``dry_m_per_s`` (b), ``quadratic_per_m_s`` (c) and their F statistics ``dry_f``,
        ``quadratic_f`` (NaN with fewer than 8 peaks).
    """
    keys = ('dry_m_per_s', 'quadratic_per_m_s', 'dry_f', 'quadratic_f')
    if t.size < 8:
        return dict.fromkeys(keys, float('nan'))
    rate = -(amplitude[2:] - amplitude[:-2]) / (t[2:] - t[:-2])
    amp = amplitude[1:-1]

    def fit(*columns: np.ndarray) -> tuple[float, np.ndarray]:
        design = np.column_stack(columns)
        coef, *_ = np.linalg.lstsq(design, rate, rcond=None)
        return float(np.sum((rate - design @ coef) ** 2)), coef

    sse_viscous, _ = fit(amp)
    sse_dry, dry = fit(amp, np.ones_like(amp))
    sse_quadratic, quadratic = fit(amp, amp**2)
    dof = amp.size - 2
    return {
        'dry_m_per_s': float(dry[1]),
        'quadratic_per_m_s': float(quadratic[1]),
        'dry_f': (sse_viscous - sse_dry) / max(sse_dry / dof, 1e-300),
        'quadratic_f': (sse_viscous - sse_quadratic) / max(sse_quadratic / dof, 1e-300),
    }


def envelope_rates(t: np.ndarray, amplitude: np.ndarray) -> tuple[float, float]:
    """The viscous and dry decay terms of the peaks: ``-dA/dt = a A + b`` by least squares.

    The classic separation of the two losses: a viscous one takes a fixed share of the
    amplitude per cycle (``a``, proportional to the damping), dry friction a fixed amount
    (``b``, proportional to its torque, by harmonic balance).

    Args:
        t: Peak times, s (both signs of the swing).
        amplitude: Peak amplitudes, m.

    Returns:
        ``(a, b)`` in 1/s and m/s (NaN with fewer than 8 peaks).
    """
    if t.size < 8:
        return float('nan'), float('nan')
    rate = -(amplitude[2:] - amplitude[:-2]) / (t[2:] - t[:-2])
    amp = amplitude[1:-1]
    coef, *_ = np.linalg.lstsq(np.column_stack([amp, np.ones_like(amp)]), rate, rcond=None)
    return float(coef[0]), float(coef[1])


def envelope_law(terms: dict[str, float]) -> str:
    """``'linear'``, ``'amplitude_dependent'`` or ``'exponential'`` from :func:`envelope_terms`."""
    dry = terms['dry_m_per_s'] > 0.0 and terms['dry_f'] > ENVELOPE_F
    quadratic = terms['quadratic_per_m_s'] > 0.0 and terms['quadratic_f'] > ENVELOPE_F
    if dry and (not quadratic or terms['dry_f'] >= terms['quadratic_f']):
        return 'linear'
    if quadratic:
        return 'amplitude_dependent'
    return 'exponential'


def decay_peaks(
    t: np.ndarray, z: np.ndarray, start_s: float, level: float
) -> tuple[np.ndarray, np.ndarray]:
    """Times and heights of the swing's peaks (both signs) after ``start_s + SETTLE_S``.

    The peaks of :mod:`~lumpbeam_ros.core.ident.peaks` (lobes beyond ``PEAK_HYSTERESIS`` noise
    sigmas, each peak a parabola's vertex), those lost in the noise left out.

    Args:
        t: Stamps, s.
        z: Tip z, m.
        start_s: The load event.
        level: The level the decay settles to, m.

    Returns:
        Peak times and absolute amplitudes about ``level``.
    """
    keep = t >= start_s + SETTLE_S
    tt, swing = t[keep], z[keep] - level
    peaks = lobe_peaks(swing, PEAK_HYSTERESIS * difference_noise_std(swing), 'both')
    if peaks.size == 0:
        return np.empty(0), np.empty(0)
    peak_t, height = vertices(tt, swing, peaks)
    amplitude = np.abs(height)
    # Peaks lost in the noise are not an envelope.
    floor = 10.0 * float(np.median(np.abs(np.diff(swing)))) + 1e-12
    big = amplitude > floor
    return peak_t[big], amplitude[big]


def time_shift(record: Record, model: TipTrajectory) -> float:
    """Delay of the measurement against the model around the first load event, s.

    The model is shifted on a 0.5 ms grid within +-``MAX_SHIFT_S`` (by interpolation) and
    the shift with the smallest z residual over the first half second after the event wins.

    Args:
        record: The measurement.
        model: A simulation at its stamps.

    Returns:
        The shift (positive: the measurement is late).
    """
    event = record.event_time_s
    keep = (record.t >= event - 0.05) & (record.t <= event + 0.5)
    shifts = np.arange(-MAX_SHIFT_S, MAX_SHIFT_S + 1e-9, 5e-4)
    costs = [
        float(np.sum((np.interp(record.t[keep] - s, model.t, model.z) - record.z[keep]) ** 2))
        for s in shifts
    ]
    return float(shifts[int(np.argmin(costs))])


def slope_ratio(t: np.ndarray, z: np.ndarray, pitch: np.ndarray, start_s: float) -> float:
    """Regression slope of pitch on z over the free decay (rad per m)."""
    keep = t >= start_s + SETTLE_S
    zz = z[keep] - z[keep].mean()
    return float(np.dot(zz, pitch[keep] - pitch[keep].mean()) / np.dot(zz, zz))


def _frequency_drift(t: np.ndarray, z: np.ndarray, start_s: float) -> float:
    middle = start_s + SETTLE_S + 0.5 * (t[-1] - start_s - SETTLE_S)
    first = decay_mode(t[t < middle], z[t < middle], start_s)
    second = decay_mode(t[t >= middle], z[t >= middle], middle - SETTLE_S)
    mean = 0.5 * (first.damped_frequency_hz + second.damped_frequency_hz)
    return (first.damped_frequency_hz - second.damped_frequency_hz) / mean


def signatures(record: Record, model: TipTrajectory, level: float) -> Signatures:
    """Measures every signature of a record against a model.

    Args:
        record: The measurement.
        model: The (nominal) model at the record's stamps.
        level: The level the measured decay settles to (the decay fit's offset), m.

    Returns:
        The signatures; a figure that cannot be measured (too short a decay) is NaN.
    """
    event = record.event_time_s
    peak_t, peak_a = decay_peaks(record.t, record.z, event, level)
    terms = envelope_terms(peak_t, peak_a)
    try:
        drift = _frequency_drift(record.t, record.z, event) - _frequency_drift(
            model.t, model.z, event
        )
    except LumpbeamError:
        drift = float('nan')
    residual = model.z - record.z
    tail = record.t >= record.t[-1] - 0.2 * (record.t[-1] - event)
    return Signatures(
        envelope=envelope_law(terms),
        envelope_terms=terms,
        frequency_drift=float(drift),
        time_shift_s=time_shift(record, model),
        slope_ratio_error=slope_ratio(record.t, record.z, record.pitch, event)
        / slope_ratio(model.t, model.z, model.pitch, event)
        - 1.0,
        static_offset_before_m=float(np.mean(residual[record.t < event])),
        static_offset_after_m=float(np.mean(residual[tail])),
    )
