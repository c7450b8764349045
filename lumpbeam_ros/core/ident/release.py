"""Finding the load release of a drop test (paper section B.3.2) in a window of tip poses.

The release instant always comes from the tip poses: a quiet static level, then the onset
of the free response, fitted to a fraction of a frame (:mod:`~lumpbeam_ros.core.ident.onset`).
``/tip_load`` is only the hint that a release happened and how much mass left: a reading
arrives late, early or not at all (``Float64`` has no stamp), so a drop in the readings
opens a search from ``release.hint_late_s`` before it to ``release.hint_early_s`` after it.
A release with no reading is found in the data alone; a reading the tip does not answer,
a tip still swinging from an earlier release, a load hung again and a load that never left
each end in a message, never in a release time presented as certain.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.bagio.tipseries import LoadSeries
from lumpbeam_ros.core.ident.covariance import mean_with_std
from lumpbeam_ros.core.ident.onset import fit_onset
from lumpbeam_ros.core.ident.samples import PoseWindow
from lumpbeam_ros.core.ident.settings import IdentifierConfig

# Load changes smaller than this (kg) are reading noise, not a drop.
_LOAD_TOLERANCE_KG = 1e-6
# The tip leaves the static level when it is this many noise sigmas off it for _PERSIST
# consecutive samples; a stretch is static when its spread is within _QUIET_RATIO times
# its sample noise (an oscillation's spread is many times its sample-to-sample noise).
_DEPARTURE_SIGMAS = 6.0
_PERSIST = 3
_QUIET_RATIO = 3.0
# Confidence of a release whose timing or mass rests on /tip_load alone.
_HINT_ONLY_CONFIDENCE = 0.2


@dataclass(frozen=True)
class Release:
    """A release and the static level before it.

    Attributes:
        time_s: When the load left, s (NaN when none was found).
        time_std_s: Its standard deviation from the onset fit, s (NaN when not fitted).
        confidence: 0..1; 1 for a clear onset in the data (announced by ``/tip_load`` when
            there are readings), lower when the two disagree or the step is small.
        source: ``'tip_load'`` (announced by ``/tip_load``, timed from the data), ``'data'``
            (found in the data alone), ``'none'``, or ``'joint_states'`` (where an arm's joints
            stopped, :mod:`~lumpbeam_ros.core.ident.ring_down`).
        load_kg: The mass released, kg (NaN when only the data saw it).
        load_after_kg: The mass still hanging after the release, kg (NaN when unknown).
        level_before_m: Mean tip z over the quiet stretch before the release.
        level_before_std_m: Its standard error (allowing for correlated noise).
        pitch_before_rad: Mean tip pitch over the same stretch (NaN without pitch).
        pitch_before_std_rad: Its standard error.
        quiet_samples: Samples in that stretch.
        step_snr: The first peak of the tip over the quiet stretch's noise.
        decay_start_s: Where the free decay may be fitted from, s (NaN: the release time
            plus ``fit.skip_after_release_s``).
        decay_end_s: Where the free decay ends (a load hung again), s.
        message: Why no release was found, or what limits the confidence.
    """

    time_s: float = float('nan')
    time_std_s: float = float('nan')
    confidence: float = 0.0
    source: str = 'none'
    load_kg: float = float('nan')
    load_after_kg: float = float('nan')
    level_before_m: float = float('nan')
    level_before_std_m: float = float('nan')
    pitch_before_rad: float = float('nan')
    pitch_before_std_rad: float = float('nan')
    quiet_samples: int = 0
    step_snr: float = float('nan')
    decay_start_s: float = float('nan')
    decay_end_s: float = math.inf
    message: str = ''

    @property
    def found(self) -> bool:
        """Whether a release time is known."""
        return math.isfinite(self.time_s)


@dataclass(frozen=True)
class LoadChange:
    """A change of the ``/tip_load`` readings: the hint of a release or of a load hung.

    Attributes:
        time_s: Stamp of the first reading with the new value, s.
        before_kg: The mass before, kg.
        after_kg: The mass after, kg.
    """

    time_s: float
    before_kg: float
    after_kg: float

    @property
    def released_kg(self) -> float:
        """Mass that left (negative when a load was hung)."""
        return self.before_kg - self.after_kg


@dataclass(frozen=True)
class _Step:
    """A departure of the tip from a quiet static level, seen in the data."""

    departure: int
    quiet_start: int
    level: float
    noise: float
    rising: bool


def load_changes(loads: LoadSeries) -> list[LoadChange]:
    """The changes in a series of ``/tip_load`` readings, oldest first."""
    kg = loads.kg
    changed = np.flatnonzero(np.abs(np.diff(kg)) > _LOAD_TOLERANCE_KG) + 1
    return [LoadChange(float(loads.t[k]), float(kg[k - 1]), float(kg[k])) for k in changed]


def detect_release(window: PoseWindow, config: IdentifierConfig) -> Release:
    """Finds the last release in a window: timed from the data, hinted by ``/tip_load``.

    Args:
        window: Cleaned tip poses (and load readings).
        config: Thresholds (``min_step_snr``, ``min_quiet_s``) and the hint's reach
            (``hint_late_s``, ``hint_early_s``).

    Returns:
        The release; ``source == 'none'`` with a message when there is none.
    """
    scan = _Scan(window, config)
    changes = [c for c in load_changes(window.loads) if c.time_s <= window.end_s]
    drops = [c for c in changes if c.released_kg > 0.0]
    if scan.message and drops:
        return _unanswered(drops[-1], scan.message, config, window.end_s)
    if scan.message:
        return Release(message=scan.message)
    if drops:
        release = _from_hint(scan, drops[-1], config)
    else:
        release = scan.last_release()
        if release.found and len(window.loads):
            release = _unannounced(release, window.loads)
    if release.found:
        release = _until_next_load(release, changes, scan, config)
    return release


def _from_hint(scan: _Scan, drop: LoadChange, config: IdentifierConfig) -> Release:
    """The release a ``/tip_load`` drop announces, timed from the data."""
    low, high = drop.time_s - config.hint_late_s, drop.time_s + config.hint_early_s
    near = [s for s in scan.steps if s.rising and low <= scan.t[s.departure] <= high]
    if near:
        release = scan.release(near[-1], 'tip_load')
        if not release.found:
            return release
        return replace(release, load_kg=drop.released_kg, load_after_kg=drop.after_kg)
    quiet = scan.quiet_between(low, high)
    earlier = [s for s in scan.steps if s.rising and scan.t[s.departure] < low]
    if not quiet and earlier:
        before = scan.t[earlier[-1].departure - 1]
        return Release(
            time_s=drop.time_s,
            confidence=_HINT_ONLY_CONFIDENCE,
            source='tip_load',
            decay_start_s=high,
            message=(
                f'the tip was still moving (since the release at {before:.3f} s) when '
                f'/tip_load dropped at {drop.time_s:.3f} s: release time only from /tip_load, '
                'no static level before it'
            ),
            load_kg=drop.released_kg,
            load_after_kg=drop.after_kg,
        )
    found = scan.last_release()
    if found.found:
        gap = found.time_s - drop.time_s
        return replace(
            found,
            confidence=0.5 * found.confidence,
            message=(
                f'/tip_load dropped at {drop.time_s:.3f} s, {gap:+.3f} s from the release the '
                f'tip shows at {found.time_s:.3f} s'
            ),
            load_kg=drop.released_kg,
            load_after_kg=drop.after_kg,
        )
    return _unanswered(drop, found.message, config, float(scan.t[-1]))


def _unanswered(
    drop: LoadChange, why: str, config: IdentifierConfig, end_s: float = -math.inf
) -> Release:
    """No release: ``/tip_load`` dropped but the tip shows no release near it."""
    pending = ' (yet)' if drop.time_s + config.hint_early_s > end_s else ''
    return Release(
        message=(
            f'/tip_load shows a release of {drop.released_kg:.3g} kg at {drop.time_s:.3f} s, '
            f'but the tip does not{pending}: {why}'
        )
    )


def _unannounced(release: Release, loads: LoadSeries) -> Release:
    """A release in the data while ``/tip_load`` shows none: the mass that left is unknown."""
    before = loads.kg[loads.t <= release.time_s]
    reading = float(before[-1]) if before.size else float(loads.kg[0])
    return replace(
        release,
        confidence=0.5 * release.confidence,
        message=(
            f'/tip_load shows no drop ({reading:.3g} kg at the release), but the tip does: '
            'the released mass is assumed'
        ),
    )


def _until_next_load(
    release: Release, changes: list[LoadChange], scan: _Scan, config: IdentifierConfig
) -> Release:
    """Ends the free decay where a load is hung again (in the data or on ``/tip_load``)."""
    end = math.inf
    hung = [c for c in changes if c.released_kg < 0.0 and c.time_s > release.time_s]
    if hung:
        # The reading may be late by up to hint_late_s: the decay surely ended after that.
        end = max(hung[0].time_s - config.hint_late_s, release.time_s)
    falls = [s for s in scan.steps if not s.rising and scan.t[s.departure] > release.time_s]
    if falls:
        end = min(end, float(scan.t[falls[0].quiet_start]))
    return replace(release, decay_end_s=end)


class _Scan:
    """Every departure of the tip from a quiet static level in a window.

    For each sample the preceding ``min_quiet_s`` (at least ``_PERSIST + 1`` samples) give a
    level, a sample noise (from first differences: var = 2 sigma^2) and a spread; where the
    spread is within ``_QUIET_RATIO`` noise sigmas the tip was static, and the first of
    ``_PERSIST`` samples more than ``_DEPARTURE_SIGMAS`` off the level starts a step.
    """

    def __init__(self, window: PoseWindow, config: IdentifierConfig):
        self.window = window
        self.config = config
        self.t, self.z = window.t, window.z
        self.steps: list[_Step] = []
        self.message = ''
        n = self.t.size
        dt = float(np.median(np.diff(self.t))) if n > 1 else math.inf
        q = max(_PERSIST + 1, int(round(config.min_quiet_s / dt))) if math.isfinite(dt) else n
        self.q = q
        if n < 2 * q + _PERSIST:
            self.message = 'too few samples to look for a release'
            self.quiet = np.zeros(n, dtype=bool)
            return
        z = self.z - np.median(self.z)
        # Each sample's preceding q samples, and their q - 1 differences. Rolling sums would
        # be linear in n, but over a long window their differences cancel: beside a
        # centimetre swing, a static level's nanometre spread (a noise-free camera) is lost to
        # rounding and no stretch looks quiet.
        before = np.lib.stride_tricks.sliding_window_view(z, q)[: n - q]
        steps = np.lib.stride_tricks.sliding_window_view(np.diff(z), q - 1)[: n - q]
        i = np.arange(q, n)
        mean = before.mean(axis=1)
        spread = before.std(axis=1)
        noise = np.sqrt(np.einsum('ij,ij->i', steps, steps) / (2.0 * (q - 1)))
        noise = np.maximum(noise, 1e-12)
        quiet = spread <= _QUIET_RATIO * noise
        self.quiet = np.concatenate([np.zeros(q, dtype=bool), quiet])
        offset = z[i] - mean
        off = np.abs(offset) > _DEPARTURE_SIGMAS * noise
        run = off.copy()
        for k in range(1, _PERSIST):
            later = np.zeros_like(off)
            ahead = z[q + k :] - mean[: n - q - k]
            later[: n - q - k] = (np.abs(ahead) > _DEPARTURE_SIGMAS * noise[: n - q - k]) & (
                np.sign(ahead) == np.sign(offset[: n - q - k])
            )
            run &= later
        starts = np.flatnonzero(quiet & run)
        # One step per event: a start within q samples of the previous one is the same step.
        keep = np.ones(starts.size, dtype=bool)
        keep[1:] = np.diff(starts) > q
        median = float(np.median(self.z))
        for k in starts[keep]:
            departure = int(k + q)
            level = float(mean[k]) + median
            self.steps.append(
                _Step(
                    departure=departure,
                    quiet_start=self._quiet_start(departure, level, float(noise[k])),
                    level=level,
                    noise=float(noise[k]),
                    rising=bool(offset[k] > 0.0),
                )
            )
        if not self.steps:
            self.message = (
                'no step in the tip level: no release in the window'
                if np.all(quiet)
                else 'no quiet static level before the tip moves: no release in the window'
            )

    def _quiet_start(self, departure: int, level: float, noise: float) -> int:
        """First index of the static stretch that ends at ``departure``."""
        off = np.abs(self.z[:departure] - level) > _DEPARTURE_SIGMAS * noise
        outside = np.flatnonzero(off)
        return int(outside[-1] + 1) if outside.size else 0

    def quiet_between(self, low: float, high: float) -> bool:
        """Whether the tip was static anywhere from ``low`` to ``high``."""
        inside = (self.t >= low) & (self.t <= high)
        return bool(np.any(self.quiet[inside]))

    def last_release(self) -> Release:
        """The last rising step, or why there is none."""
        rising = [s for s in self.steps if s.rising]
        if not rising:
            return Release(message='the tip level falls: a load was added, not released')
        return self.release(rising[-1], 'data')

    def release(self, step: _Step, source: str) -> Release:
        """The release of one step: its onset fitted, its static level and confidence."""
        t, z = self.t, self.z
        config = self.config
        reach = step.departure + int(round(0.5 / config.min_frequency_hz / self._dt()))
        stop = min(reach, t.size)
        segment = z[step.departure : stop]
        peak = step.departure + int(np.argmax(segment if step.rising else -segment))
        rise = abs(float(z[peak]) - step.level)
        if peak >= t.size - 1 and stop < reach:
            # Too early for the onset fit: the last static sample, to a frame.
            time_s = float(t[step.departure - 1])
            before = np.arange(step.quiet_start, step.departure)
            base = Release(time_s=time_s, time_std_s=self._dt(), source=source)
            message = 'the window ends before the first peak after the release: timed to a frame'
            return _with_levels(base, self.window, before, 1.0, message, rise / step.noise)
        snr = rise / step.noise
        if snr < config.min_step_snr:
            return Release(
                message=f'the tip rose only {snr:.1f} noise sigmas: no clear release',
                step_snr=snr,
            )
        first = max(step.quiet_start, step.departure - self.q)
        try:
            onset = fit_onset(t, z, step.departure, first, peak)
        except LumpbeamError as exc:
            return Release(message=f'the onset of the release cannot be fitted: {exc}')
        before = np.arange(step.quiet_start, step.departure)
        before = before[t[before] < onset.time_s]
        quiet_s = float(onset.time_s - t[step.quiet_start])
        # Heuristic confidence: 0 at the SNR threshold, 1 an order of magnitude above it, scaled
        # down when the quiet stretch is shorter than twice the minimum.
        confidence = min(1.0, math.log10(snr / config.min_step_snr)) if snr > 0 else 0.0
        confidence *= min(1.0, quiet_s / (2.0 * config.min_quiet_s))
        base = Release(time_s=onset.time_s, time_std_s=onset.time_std_s, source=source)
        return _with_levels(base, self.window, before, confidence, '', snr)

    def _dt(self) -> float:
        return float(np.median(np.diff(self.t)))


def _with_levels(
    base: Release,
    window: PoseWindow,
    before: np.ndarray,
    confidence: float,
    message: str,
    snr: float = float('nan'),
) -> Release:
    level, level_std = mean_with_std(window.z[before]) if before.size else (math.nan, math.nan)
    pitch = window.pitch[before]
    if pitch.size and np.all(np.isfinite(pitch)):
        pitch_mean, pitch_std = mean_with_std(pitch)
    else:
        pitch_mean, pitch_std = math.nan, math.nan
    return replace(
        base,
        confidence=confidence,
        level_before_m=level,
        level_before_std_m=level_std,
        pitch_before_rad=pitch_mean,
        pitch_before_std_rad=pitch_std,
        quiet_samples=int(before.size),
        step_snr=snr,
        message=message,
    )
