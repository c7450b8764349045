"""The peaks of a decaying oscillation: the one peak finder of the package.

A lobe is a run of same-sign samples among those beyond a hysteresis band about the level
the oscillation decays to, so noise near the level does not split one; its peak is the
vertex of a parabola fitted to the samples within a tenth of a period of its highest
sample. The paper's log decrement (B.20, :mod:`~lumpbeam_ros.core.ident.logdec`) takes the
positive peaks, the diagnosis's envelope signature
(:func:`~lumpbeam_ros.core.diagnose.signatures.decay_peaks`) those of both signs.
"""

from __future__ import annotations

import numpy as np


def lobe_peaks(s: np.ndarray, threshold: float, signs: str = 'positive') -> np.ndarray:
    """Indices of the highest sample of each lobe beyond ``threshold``, in time order.

    Args:
        s: Samples about the level (the level subtracted).
        threshold: Half width of the hysteresis band (>= 0).
        signs: ``'positive'`` lobes only, or ``'both'`` (a negative lobe's lowest sample).

    Returns:
        Sample indices (empty when no sample leaves the band).
    """
    marked = np.flatnonzero(np.abs(s) > threshold)
    if marked.size == 0:
        return np.empty(0, dtype=int)
    positive = s[marked] > 0.0
    starts = np.flatnonzero(np.r_[True, positive[1:] != positive[:-1]])
    ends = np.r_[starts[1:], marked.size]
    peaks = []
    for lo, hi in zip(starts, ends, strict=True):
        if not positive[lo] and signs == 'positive':
            continue
        lobe = s[marked[lo] : marked[hi - 1] + 1]
        highest = np.argmax(lobe) if positive[lo] else np.argmin(lobe)
        peaks.append(marked[lo] + int(highest))
    return np.asarray(peaks, dtype=int)


def vertices(t: np.ndarray, s: np.ndarray, peaks: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Peak times and heights: vertices of parabolas fitted around samples ``peaks``.

    Each parabola spans a tenth of a period on each side of its peak, where it stays within
    2 % of a cosine's top; the fits are solved together as one batch of 3 x 3 systems. A
    fit that does not curve the peak's way, or whose vertex leaves its span, keeps the
    sample.

    Args:
        t: Increasing stamps, s.
        s: Samples about the level.
        peaks: Indices of the peaks (:func:`lobe_peaks`), in time order.

    Returns:
        The times and the (signed) heights.
    """
    period = float(np.median(np.diff(t[peaks]))) if peaks.size > 1 else 0.0
    if peaks.size > 1 and np.any(s[peaks] < 0.0) and np.any(s[peaks] > 0.0):
        period *= 2.0  # peaks of both signs come twice a period
    dt = float(np.median(np.diff(t)))
    half = max(1, int(round(0.1 * period / dt)))
    idx = np.clip(peaks[:, None] + np.arange(-half, half + 1), 0, t.size - 1)
    tc = t[idx] - t[peaks][:, None]
    sign = np.where(s[peaks] < 0.0, -1.0, 1.0)
    sv = s[idx] * sign[:, None]  # every peak a maximum
    powers = tc[:, :, None] ** np.arange(5)
    moments = powers.sum(axis=1)
    normal = np.stack([moments[:, i : i + 3] for i in range(3)], axis=1)
    rhs = np.einsum('pk,pkj->pj', sv, powers[:, :, :3])
    times = t[peaks].astype(float)
    heights = s[peaks].astype(float)
    try:
        c0, c1, c2 = np.linalg.solve(normal, rhs[:, :, None])[:, :, 0].T
    except np.linalg.LinAlgError:
        return times, heights
    shift = -c1 / (2.0 * np.where(c2 < 0.0, c2, -1.0))
    good = (c2 < 0.0) & (np.abs(shift) <= np.ptp(tc, axis=1))
    times[good] += shift[good]
    heights[good] = (sign * (c0 - c1 * c1 / (4.0 * c2)))[good]
    return times, heights
