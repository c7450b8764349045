"""Finding the load release of a drop test (paper section B.3.2) in a window of tip poses.

With ``/tip_load`` readings the release is where the hanging mass drops. Without them it is
found in the data: a quiet static level, then a rise of the tip (the load is gone, the beam
springs up) followed by a free decay about a higher level.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from lumpbeam_ros.ident.config import IdentifierConfig
from lumpbeam_ros.ident.covariance import mean_with_std
from lumpbeam_ros.ident.samples import PoseWindow

# Load changes smaller than this (kg) are reading noise, not a drop.
_LOAD_TOLERANCE_KG = 1e-6
# A release is where the tip leaves the static level by this many noise sigmas for
# _PERSIST consecutive samples.
_DEPARTURE_SIGMAS = 6.0
_PERSIST = 3


@dataclass(frozen=True)
class Release:
    """A release and the static level before it.

    Attributes:
        time_s: When the load left, s (NaN when none was found).
        confidence: 0..1; 1 for a ``/tip_load`` drop the tip answers, lower for a step found
            in the data with little margin over the noise.
        source: ``'tip_load'``, ``'data'`` or ``'none'``.
        load_kg: The mass released, kg (NaN when only the data saw it).
        load_after_kg: The mass still hanging after the release, kg (NaN when unknown).
        level_before_m: Mean tip z over the quiet stretch before the release.
        level_before_std_m: Its standard error (allowing for correlated noise).
        pitch_before_rad: Mean tip pitch over the same stretch (NaN without pitch).
        pitch_before_std_rad: Its standard error.
        quiet_samples: Samples in that stretch.
        step_snr: The rise of the tip over the quiet stretch's noise.
        message: Why no release was found, or what limits the confidence.
    """

    time_s: float = float('nan')
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
    message: str = ''

    @property
    def found(self) -> bool:
        """Whether a release time is known."""
        return math.isfinite(self.time_s)


def detect_release(window: PoseWindow, config: IdentifierConfig) -> Release:
    """Finds the last release in a window, from ``/tip_load`` if present, else from the data.

    When ``/tip_load`` readings show no drop but the data show a release, the data's release
    is returned with half its confidence and a message.

    Args:
        window: Cleaned tip poses (and load readings).
        config: Thresholds (``min_step_snr``, ``min_quiet_s``).

    Returns:
        The release; ``source == 'none'`` with a message when there is none.
    """
    if len(window.loads) >= 2:
        release = _from_loads(window, config)
        if release.found:
            return release
        # Readings that never drop may be stale or mislabelled: trust the tip, but say so.
        found = _from_data(window, config)
        if found.found:
            return replace(
                found,
                confidence=0.5 * found.confidence,
                message='/tip_load shows no drop, but the tip does',
            )
        return release
    return _from_data(window, config)


def _from_loads(window: PoseWindow, config: IdentifierConfig) -> Release:
    t_load, kg = window.loads.t, window.loads.kg
    drops = np.flatnonzero(np.diff(kg) < -_LOAD_TOLERANCE_KG) + 1
    drops = drops[t_load[drops] <= window.end_s]
    if drops.size == 0:
        return Release(message='/tip_load shows no drop of the load')
    k = int(drops[-1])
    time_s = float(t_load[k])
    released, after = float(kg[k - 1] - kg[k]), float(kg[k])
    # The quiet stretch starts after the previous load change, if the window shows one.
    changes = np.flatnonzero(np.abs(np.diff(kg[:k])) > _LOAD_TOLERANCE_KG)
    start = float(t_load[changes[-1] + 1]) if changes.size else -math.inf
    before = np.flatnonzero((window.t < time_s) & (window.t >= start))
    base = Release(time_s=time_s, source='tip_load', load_kg=released, load_after_kg=after)
    if before.size < 2:
        return _with_levels(
            base, window, before, 0.5, 'no poses before the release: no static deflection'
        )
    level, noise = float(np.mean(window.z[before])), _noise(window.z[before])
    after_idx = np.flatnonzero(window.t >= time_s)
    rise = float(np.mean(window.z[after_idx]) - level) if after_idx.size else float('nan')
    snr = rise / noise if noise > 0 else math.inf
    if not snr >= config.min_step_snr:
        return _with_levels(
            base,
            window,
            before,
            0.3,
            f'/tip_load shows a release at {time_s:.3f} s but the tip rose only '
            f'{snr:.1f} noise sigmas',
            snr,
        )
    return _with_levels(base, window, before, 1.0, '', snr)


def _from_data(window: PoseWindow, config: IdentifierConfig) -> Release:
    t, z = window.t, window.z
    n = t.size
    dt = float(np.median(np.diff(t))) if n > 1 else math.inf
    margin = max(_PERSIST + 1, int(config.min_quiet_s / dt)) if math.isfinite(dt) else n
    if n < 2 * margin:
        return Release(message='too few samples to look for a release')
    split = _best_split(z, margin)
    quiet = z[: split - _PERSIST]
    level = float(np.median(quiet))
    noise = _noise(quiet)
    beyond = np.abs(z - level) > _DEPARTURE_SIGMAS * max(noise, 1e-12)
    run = beyond[: n - _PERSIST + 1].copy()
    for k in range(1, _PERSIST):
        run &= beyond[k : n - _PERSIST + 1 + k]
    leaving = np.flatnonzero(run)
    if leaving.size == 0:
        return Release(message='no step in the tip level: no release in the window')
    r = int(leaving[0])
    if r < 2 or t[r - 1] - t[0] < config.min_quiet_s:
        return Release(message='the window does not start with a quiet static level')
    # The last sample on the static level; the release happened between it and the next.
    time_s = float(t[r - 1])
    before = np.arange(r)
    quiet_std = float(np.std(z[:r]))
    rise = float(np.mean(z[r:]) - np.mean(z[:r]))
    snr = rise / max(noise, 1e-12)
    if quiet_std > 3.0 * max(noise, 1e-12):
        return Release(message='the tip moves before the step: no quiet static level')
    if rise <= 0.0:
        return Release(message='the tip level falls: a load was added, not released')
    if snr < config.min_step_snr:
        return Release(
            message=f'the tip rose only {snr:.1f} noise sigmas: no clear release', step_snr=snr
        )
    # Heuristic confidence: 0 at the SNR threshold, 1 an order of magnitude above it, scaled
    # down when the quiet stretch is shorter than twice the minimum.
    confidence = min(1.0, math.log10(snr / config.min_step_snr))
    confidence *= min(1.0, (time_s - t[0]) / (2.0 * config.min_quiet_s))
    base = Release(time_s=time_s, source='data')
    return _with_levels(base, window, before, confidence, '', snr)


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
    return Release(
        time_s=base.time_s,
        confidence=confidence,
        source=base.source,
        load_kg=base.load_kg,
        load_after_kg=base.load_after_kg,
        level_before_m=level,
        level_before_std_m=level_std,
        pitch_before_rad=pitch_mean,
        pitch_before_std_rad=pitch_std,
        quiet_samples=int(before.size),
        step_snr=snr,
        message=message,
    )


def _best_split(z: np.ndarray, margin: int) -> int:
    """Index splitting ``z`` into two constant levels with the least squared error.

    After a release the tip starts at the old level and swings about the new one, so the
    split lands within the first half-cycle after the release; the caller walks back from
    it to where the tip left the old level.
    """
    centred = z - np.median(z)
    s1 = np.cumsum(centred)
    s2 = float(centred @ centred)
    total = s1[-1]
    k = np.arange(margin, z.size - margin)
    left = s1[k - 1]
    cost = s2 - left**2 / k - (total - left) ** 2 / (z.size - k)
    return int(k[np.argmin(cost)])


def _noise(values: np.ndarray) -> float:
    """Sample noise of a (nearly) static stretch, from first differences (var = 2 sigma^2)."""
    if values.size < 3:
        return float('nan')
    d = np.diff(values)
    return float(1.4826 * np.median(np.abs(d - np.median(d))) / math.sqrt(2.0))
