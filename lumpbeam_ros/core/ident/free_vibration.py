"""The free vibrations of any record: where they start, their modes, and the steady lines.

A lab's record is not always a drop test: a beam is tapped, plucked or struck, a shaker is
switched off, an arm stops. Whatever started it, a free vibration is a sum of damped modes
from where the excitation ended until it dies in the noise; a steady line (mains hum, a fan,
a shaker still running) does not decay and is never a mode. The record is analysed in three
steps, each from the data alone, once a straight line through the record (a sensor's drift)
is taken out:

1. **Lines** (:func:`steady_lines`): a spectral peak that stands out in every quarter of the
   record with about the same amplitude does not decay. Each is fitted as a sinusoid over the
   whole record and taken out of it.
2. **Free vibrations** (:func:`find_free_vibrations`): the RMS envelope of what is left,
   over two periods of its strongest frequency, against its floor (the quietest twentieth of
   the record). A rise of more than :data:`RISE_FACTOR` over the lowest level since the last
   one starts an excitation; its free vibration runs from where the envelope leaves its top
   (the excitation's end) until it sinks back to twice the floor, or the next excitation.
3. **Modes** (:func:`identify_free_vibration`): the damped-sinusoid least squares of
   :mod:`~lumpbeam_ros.core.ident.sinusoid` from the strongest spectral peak of the band,
   then one mode at a time while each stands out of the noise (:func:`~.modes.choose_modes`),
   with the correlation-robust standard deviations of :mod:`~.covariance`. No beam model
   enters: its backbone applies to the drop test of the configured beam, not to an unknown
   structure.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.bagio.tipseries import SampleCounts
from lumpbeam_ros.core.ident.identification import (
    AnalysedWindow,
    Estimate,
    Estimates,
    Identification,
    IdentifiedMode,
    Status,
)
from lumpbeam_ros.core.ident.modes import choose_modes, structural_modes
from lumpbeam_ros.core.ident.settings import MAX_MODES_LIMIT, IdentifierConfig
from lumpbeam_ros.core.ident.sinusoid import (
    DampedSinusoidFit,
    DampedSinusoidParameters,
    spectral_peak_hz,
)

#: Highest frequency looked for, as a fraction of the Nyquist frequency (above it a mode's
#: few samples per period leave its damping undetermined).
NYQUIST_FRACTION = 0.9
#: Parts of the record whose spectra must each show a line, with about the same amplitude.
LINE_PARTS = 4
#: A line's amplitude may vary by this factor between the parts (a mode decays by more).
LINE_STEADINESS = 1.2
#: A line stands this many times above the spectrum's median in every part.
LINE_PROMINENCE = 30.0
#: Most lines reported.
MAX_LINES = 8
#: An excitation is an envelope rise by this factor over its lowest level since the last.
RISE_FACTOR = 4.0
#: A free vibration ends where the envelope sinks to this many times its floor.
END_FACTOR = 2.0
#: The envelope's floor: this quantile of it (the quietest part of the record).
FLOOR_QUANTILE = 0.05
#: A free vibration starts where the envelope falls below this fraction of its top.
TOP_FRACTION = 0.9
#: An excitation over within this many envelope widths (two periods each) is an impact; a
#: longer one (a forcing switched off) is of unknown kind.
SHARP_WIDTHS = 4
#: Fewest damped periods of the strongest frequency in a free vibration worth fitting.
MIN_PERIODS = 2.0
#: Fewest samples a record must have to be looked at.
MIN_SAMPLES = 16
#: Samples at the record's extreme that make it a clipped record.
CLIP_RUN = 3
#: Kinds of a free vibration's start (doc/interfaces.md).
KINDS = ('release', 'impact', 'move_end', 'unknown')


@dataclass(frozen=True)
class Line:
    """A steady line of the record: a sinusoid that does not decay (``lines`` in JSON).

    Attributes:
        frequency_hz: Its frequency, Hz.
        amplitude: Its amplitude, in the record's unit (m or m/s^2).
    """

    frequency_hz: float
    amplitude: float

    def as_dict(self) -> dict[str, float]:
        """The line as ``lumpbeam analyze`` lists it."""
        return {'frequency_hz': self.frequency_hz, 'amplitude': self.amplitude}


@dataclass(frozen=True)
class FreeVibration:
    """A stretch of the record that rings freely after an excitation.

    Attributes:
        start_s: Where the excitation ended and the free decay starts, s.
        end_s: Where it has died into the floor (or the next excitation began), s.
        kind: What started it: ``release``, ``impact``, ``move_end`` or ``unknown``.
    """

    start_s: float
    end_s: float
    kind: str


@dataclass(frozen=True)
class EventModes:
    """A free vibration and its modes (an entry of ``events`` in JSON).

    Attributes:
        event: The stretch.
        identification: Its modes and first mode's figures (status ERROR and why when none).
        fit: The least squares behind them (``None`` when it failed).
    """

    event: FreeVibration
    identification: Identification
    fit: DampedSinusoidParameters | None = None

    @property
    def duration_s(self) -> float:
        """How long it rang, s."""
        return self.event.end_s - self.event.start_s

    def as_dict(self) -> dict[str, object]:
        """``{start_s, end_s, kind, modes}`` as ``lumpbeam analyze`` lists it."""
        return {
            'start_s': self.event.start_s,
            'end_s': self.event.end_s,
            'kind': self.event.kind,
            'status': self.identification.status.name,
            'message': self.identification.message,
            'modes': [mode.as_dict() for mode in self.identification.modes],
        }


@dataclass(frozen=True)
class RecordAnalysis:
    """A whole record: its steady lines, its free vibrations and the headline figures.

    Attributes:
        lines: Steady lines, strongest first.
        events: Free vibrations by time, each identified.
        identification: The headline figures: those of the free vibration that rang
            longest with a mode, else status ERROR, why, and no figure.
    """

    lines: tuple[Line, ...]
    events: tuple[EventModes, ...]
    identification: Identification


def sample_rate_hz(t: np.ndarray) -> float:
    """The record's rate, Hz, from its median sample spacing."""
    return 1.0 / float(np.median(np.diff(t)))


def _amplitude_spectrum(y: np.ndarray, n_fft: int) -> np.ndarray:
    """One-sided amplitude spectrum of ``y`` under a Hann window (a sinusoid's amplitude)."""
    window = np.hanning(y.size)
    return np.asarray(2.0 * np.abs(np.fft.rfft((y - y.mean()) * window, n_fft)) / window.sum())


def _sinusoids(t: np.ndarray, y: np.ndarray, frequencies: Sequence[float]) -> np.ndarray:
    """Least-squares fit of the offset and a sinusoid at each frequency; the fitted values."""
    tau = t - t[0]
    columns = [np.ones_like(tau)]
    for f in frequencies:
        columns += [np.cos(2 * np.pi * f * tau), np.sin(2 * np.pi * f * tau)]
    design = np.column_stack(columns)
    coefficients, *_ = np.linalg.lstsq(design, y, rcond=None)
    return np.asarray(design @ coefficients)


def steady_lines(t: np.ndarray, y: np.ndarray) -> tuple[Line, ...]:
    """The sinusoids that run through the whole record without decaying.

    A peak counts when it stands :data:`LINE_PROMINENCE` times above the spectrum's median
    in each of :data:`LINE_PARTS` equal parts, its amplitudes within a factor
    :data:`LINE_STEADINESS` of each other.

    Args:
        t: Stamps, s (about uniform).
        y: Samples.

    Returns:
        The lines, strongest first (at most :data:`MAX_LINES`).
    """
    # The spectra on the record's own step: a sample dropped here and there would shift
    # every later one's phase and smear a line (then left behind as a "mode").
    step = 1.0 / sample_rate_hz(t)
    u = np.interp(np.arange(t[0], t[-1], step), t, y)
    part = u.size // LINE_PARTS
    if part < 64:
        return ()
    n_fft = 1 << int(math.ceil(math.log2(4 * part)))
    spectra = np.array(
        [_amplitude_spectrum(u[k * part : (k + 1) * part], n_fft) for k in range(LINE_PARTS)]
    )
    weakest, strongest = spectra.min(axis=0), spectra.max(axis=0)
    floor = np.median(spectra, axis=1).max()
    inner = weakest[1:-1]
    peaks = 1 + np.flatnonzero(
        (inner > weakest[:-2]) & (inner >= weakest[2:]) & (inner > LINE_PROMINENCE * floor)
    )
    peaks = peaks[strongest[peaks] <= LINE_STEADINESS * weakest[peaks]]
    rate = sample_rate_hz(t)
    found: list[float] = []
    for k in peaks[np.argsort(-weakest[peaks])][:MAX_LINES]:
        # The peak's centre by a parabola through the log spectrum (Hann: within 0.1 bin).
        a, b, c = np.log(spectra.mean(axis=0)[k - 1 : k + 2])
        shift = 0.5 * (a - c) / (a - 2 * b + c) if a - 2 * b + c < 0 else 0.0
        found.append((k + shift) * rate / n_fft)
    lines = []
    for f in found:
        # A frequency off by a thousandth of a bin over many periods leaves a slow beat
        # that looks like a lightly damped mode: the least-squares frequency.
        bin_hz = rate / n_fft
        best = _golden_max(
            lambda g: float(np.sum(_sinusoids(t, y, [g]) ** 2)), f - bin_hz, f + bin_hz
        )
        fitted = _sinusoids(t, y, [best])
        lines.append(Line(best, float(np.sqrt(2.0) * np.std(fitted))))
    return tuple(sorted(lines, key=lambda line: -line.amplitude))


def _golden_max(function: Callable[[float], float], low: float, high: float) -> float:
    """Where ``function`` is largest in ``[low, high]``, by golden-section search (1e-6 of it).

    A hand-made search rather than scipy's: ``lumpbeam analyze`` does not load scipy.
    """
    ratio = (math.sqrt(5.0) - 1.0) / 2.0
    a, b = low, high
    c, d = b - ratio * (b - a), a + ratio * (b - a)
    fc, fd = function(c), function(d)
    while b - a > 1e-6 * (high - low):
        if fc > fd:
            b, d, fd = d, c, fc
            c = b - ratio * (b - a)
            fc = function(c)
        else:
            a, c, fc = c, d, fd
            d = a + ratio * (b - a)
            fd = function(d)
    return 0.5 * (a + b)


def without_lines(t: np.ndarray, y: np.ndarray, lines: Sequence[Line]) -> np.ndarray:
    """The record with its steady lines (and its mean) taken out."""
    return np.asarray(y - _sinusoids(t, y, [line.frequency_hz for line in lines]))


def _envelope(y: np.ndarray, width: int) -> np.ndarray:
    """Centred moving RMS over ``width`` samples."""
    power = np.convolve(y * y, np.ones(width) / width, mode='same')
    return np.sqrt(np.maximum(power, 0.0))


def find_free_vibrations(
    t: np.ndarray, y: np.ndarray, hints: Sequence[tuple[float, str]] = ()
) -> tuple[FreeVibration, ...]:
    """The stretches of the record that ring freely, by time.

    Args:
        t: Stamps, s (about uniform).
        y: Samples without their steady lines (:func:`without_lines`).
        hints: Known excitations ``(time s, kind)``: a load change (``release``) or the end
            of a move (``move_end``); a free vibration that starts within an envelope width
            after one takes its kind.

    Returns:
        The free vibrations (none in a record of noise or of a steady forcing).
    """
    if t.size < MIN_SAMPLES:
        return ()
    # Below two cycles in the record: a trend, not a vibration.
    f = spectral_peak_hz(t, y, min_hz=2.0 / float(t[-1] - t[0]))
    if not f > 0.0:
        return ()
    width = int(np.clip(round(2.0 * sample_rate_hz(t) / f), 4, max(4, t.size // 16)))
    envelope = _envelope(y, width)
    floor = max(float(np.quantile(envelope, FLOOR_QUANTILE)), 1e-300)
    events: list[FreeVibration] = []
    n = t.size
    i = 0
    while i < n:
        onset = _next_rise(envelope, i, floor)
        if onset < 0:
            break
        # The top of the excitation (a tap's instant, a forcing's plateau) and where the
        # envelope falls from it: the excitation is over.
        top = float(envelope[onset])
        start = onset
        while start + 1 < n and envelope[start + 1] >= TOP_FRACTION * top:
            start += 1
            top = max(top, float(envelope[start]))
        # Its end: back to twice the floor, or the next rise.
        end = start
        lowest = envelope[start]
        while end + 1 < n and envelope[end + 1] > END_FACTOR * floor:
            end += 1
            lowest = min(lowest, envelope[end])
            if envelope[end] > RISE_FACTOR * max(lowest, floor):
                end = int(np.argmin(envelope[start:end])) + start
                break
        # The centred envelope's window reaches half a width past the excitation's end.
        first = min(start + width // 2, end)
        sharp = start - onset <= SHARP_WIDTHS * width
        kind = 'impact' if sharp else 'unknown'
        if sharp:
            # Short (a tap, a pluck): free from its largest swing on.
            first = onset + int(np.argmax(np.abs(y[onset : first + 1])))
        for when, hint in hints:
            if t[max(onset - width, 0)] <= when <= t[start]:
                kind = hint
                first = max(first, int(np.searchsorted(t, when)))
        if (t[end] - t[first]) * f >= MIN_PERIODS:
            events.append(FreeVibration(float(t[first]), float(t[end]), kind))
        i = max(end, start + 1)
    return tuple(events)


def _next_rise(envelope: np.ndarray, i: int, floor: float) -> int:
    """Where the envelope first rises :data:`RISE_FACTOR` over its lowest since ``i`` (-1: never).

    A record that starts ringing (its excitation before the first sample) rises at 0.
    """
    if i == 0 and envelope[0] > RISE_FACTOR * floor:
        return 0
    lowest = np.minimum.accumulate(envelope[i:])
    risen = np.flatnonzero(envelope[i:] > RISE_FACTOR * np.maximum(lowest, floor))
    return i + int(risen[0]) if risen.size else -1


def _band(t: np.ndarray, band: tuple[float, float] | None) -> tuple[float, float]:
    """The band modes are looked for in: up to :data:`NYQUIST_FRACTION` of Nyquist."""
    top = NYQUIST_FRACTION * 0.5 * sample_rate_hz(t)
    low = 2.0 / float(t[-1] - t[0])  # two cycles in the stretch
    if band is None:
        return low, top
    return max(band[0], low), min(band[1], top)


def identify_free_vibration(
    t: np.ndarray,
    y: np.ndarray,
    event: FreeVibration,
    config: IdentifierConfig,
    band: tuple[float, float] | None = None,
) -> EventModes:
    """The modes of one free vibration, each with its standard deviations.

    Args:
        t: The record's stamps, s.
        y: Its samples without steady lines.
        event: The stretch to fit.
        config: ``fit.mode_false_alarm``, ``quality.min_cycles`` and
            ``quality.warn_rel_std_damping`` (up to 8 modes and a drift, a sensor's).
        band: ``(low, high)`` Hz to look in (``None``: up to the record's Nyquist frequency).

    Returns:
        The modes (status ERROR and why when none stands out).
    """
    keep = (t >= event.start_s) & (t <= event.end_s)
    ts, ys = t[keep], y[keep]
    window = AnalysedWindow(event.start_s, event.end_s)
    samples = SampleCounts(received=int(ts.size))
    low, high = _band(ts, band) if ts.size > 2 else (math.nan, math.nan)
    if not low < high:
        return EventModes(event, _error(f'no band left to look in ({low:.3g}..{high:.3g} Hz)'))
    fit = DampedSinusoidFit(n_modes=1, drift=True, min_frequency_hz=low, max_frequency_hz=high)
    try:
        params = fit.fit(ts, ys)
    except LumpbeamError as exc:
        return EventModes(event, _error(f'no damped mode fits: {exc}', window, samples))
    first = params.mode(0)
    if not (low <= first.damped_frequency_hz <= high and 0.0 < first.damping_ratio < 0.5):
        return EventModes(
            event,
            _error(
                f'no damped mode in {low:.3g}..{high:.3g} Hz (fitted '
                f'{first.damped_frequency_hz:.4g} Hz, damping ratio {first.damping_ratio:.3g})',
                window,
                samples,
            ),
        )
    wide = replace(config, min_frequency_hz=low, max_modes=MAX_MODES_LIMIT)
    choice = choose_modes(ts, ys, params, wide)
    params = choice.params
    modes = [params.mode(m) for m in structural_modes(params)]
    modes = [m for m in modes if low <= m.damped_frequency_hz <= high]
    if not modes:
        return EventModes(event, _error('no mode in the band', window, samples), params)
    modes.sort(key=lambda m: m.natural_frequency_hz)
    identified = tuple(
        IdentifiedMode(
            Estimate(m.natural_frequency_hz, m.natural_frequency_hz_std),
            Estimate(m.damping_ratio, m.damping_ratio_std),
            m.amplitude,
        )
        for m in modes
    )
    head = modes[0]
    estimates = Estimates(
        natural_frequency_hz=identified[0].natural_frequency_hz,
        damped_frequency_hz=Estimate(head.damped_frequency_hz, head.damped_frequency_hz_std),
        damping_ratio=identified[0].damping_ratio,
        log_decrement=Estimate(head.log_decrement, head.log_decrement_std),
    )
    cycles = float(ts[-1] - ts[0]) * head.damped_frequency_hz
    status, message = Status.OK, f'{len(identified)} mode(s); {choice.refused}'
    relative = head.damping_ratio_std / head.damping_ratio
    if cycles < config.min_cycles or relative > config.warn_rel_std_damping:
        status = Status.WARN
        message = f'{cycles:.1f} cycles, damping ratio +- {100 * relative:.0f} %; ' + message
    result = Identification(
        status,
        message,
        method='free_vibration',
        estimates=estimates,
        window=replace(window, cycles=cycles),
        samples=samples,
        modes=identified,
    )
    return EventModes(event, result, params)


def _error(
    message: str, window: AnalysedWindow | None = None, samples: SampleCounts | None = None
) -> Identification:
    return Identification(
        Status.ERROR,
        message,
        window=window or AnalysedWindow(),
        samples=samples or SampleCounts(),
    )


def analyze_record(
    t: np.ndarray,
    y: np.ndarray,
    config: IdentifierConfig,
    band: tuple[float, float] | None = None,
    hints: Sequence[tuple[float, str]] = (),
) -> RecordAnalysis:
    """Lines, free vibrations and their modes of a whole record (``lumpbeam analyze``).

    Args:
        t: Increasing stamps, s.
        y: Samples (a displacement, m, or an acceleration, m/s^2).
        config: Identifier settings (see :func:`identify_free_vibration`).
        band: ``(low, high)`` Hz (``None``: up to the Nyquist frequency).
        hints: Known excitations (see :func:`find_free_vibrations`).

    Returns:
        The analysis; its identification is ERROR with the reason when nothing rang.
    """
    clipped = clipped_samples(y)
    if np.count_nonzero(~clipped) < MIN_SAMPLES:
        reason = 'flat' if y.size == 0 or np.ptp(y) == 0.0 else 'clipped almost throughout'
        return RecordAnalysis((), (), _error(f'no free vibration in the record: it is {reason}'))
    if clipped.any():
        # A clipped swing is no damped sinusoid: its samples are left out (the fits take
        # uneven stamps), and the headline says so.
        t, y = t[~clipped], y[~clipped]
    # A sensor's drift is no vibration: a straight line through the record comes out first.
    # Each fit holds a drift of its own, so that this line is no bias where it is not quite
    # the drift (a slow ring's own lean in a short record).
    y = y - np.polyval(np.polyfit(t - t[0], y, 1), t - t[0])
    lines = steady_lines(t, y)
    rest = without_lines(t, y, lines)
    found = find_free_vibrations(t, rest, hints)
    events = tuple(identify_free_vibration(t, rest, event, config, band) for event in found)
    rang = [e for e in events if e.identification.ok]
    if rang:
        headline = max(rang, key=lambda e: e.duration_s).identification
    elif events:
        worst = max(events, key=lambda e: e.duration_s).identification
        headline = _error(f'no free vibration identified: {worst.message}')
    else:
        said = f' (steady lines at {", ".join(f"{x.frequency_hz:.4g}" for x in lines)} Hz)'
        headline = _error(
            'no free vibration in the record: nothing rises out of the floor and decays'
            + (said if lines else '')
        )
    if clipped.any():
        note = f'{int(clipped.sum())} clipped samples left out'
        headline = replace(headline, message=f'{headline.message}; {note}'.lstrip('; '))
    return RecordAnalysis(lines, events, headline)


def clipped_samples(y: np.ndarray) -> np.ndarray:
    """The samples at a sensor's limit: the record's extreme, reached :data:`CLIP_RUN` times.

    A real swing reaches its largest value once; a clipped one sits on the limit.
    """
    clipped = np.zeros(y.size, dtype=bool)
    if y.size:
        for extreme in (np.max(y), np.min(y)):
            at = y == extreme
            if at.sum() >= CLIP_RUN:
                clipped |= at
    return clipped
