"""Isolated outliers of the tip's z and pitch: one bad pose must not blind a whole window.

A tracker that misreads one frame (a reflection, a torn image) gives one pose far off the
motion; a least-squares fit of the window then spends its parameters on it and the window
yields no mode for as long as the pose stays in it. A pose is an *outlier* here when it
departs from the median of its ``2 * HALF_WIDTH`` neighbours (a Hampel filter) by more than
``THRESHOLD`` robust standard deviations of all poses' departures. The robust deviation is
the larger of the scaled median absolute departure and the 90th percentile's, so a
quantized record (most departures exactly 0) is not read as noise-free. The filter removes
at most ``MAX_FRACTION`` of the poses: more departures that large are the motion itself (an
impact, a fast swing sampled coarsely), and nothing is removed.
"""

from __future__ import annotations

import warnings

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from lumpbeam_ros.core.bagio.tipseries import SampleCounts, TipSeries
from lumpbeam_ros.core.ident.samples import PoseWindow

#: Neighbours on each side whose median a pose is compared with.
HALF_WIDTH = 3
#: A departure this many robust standard deviations from the neighbours' median is an outlier.
THRESHOLD = 12.0
#: Most of a window's poses that may be outliers; past it, nothing is removed.
MAX_FRACTION = 0.01
#: Outliers next to each other are found one per pass, up to this many passes.
PASSES = 3
#: A sample is judged when its neighbours span at most this many times their even spacing.
SPAN_TOLERANCE = 1.5
#: Normal quantiles: the median absolute value and the 90th percentile of |N(0, 1)|.
_MAD_SCALE = 1.4826
_P90_SCALE = 1.0 / 1.6449


def _departures(values: np.ndarray) -> np.ndarray:
    """Each sample's distance from the median of its neighbours (NaN ones left out)."""
    padded = np.pad(values, HALF_WIDTH, mode='edge')
    windows = sliding_window_view(padded, 2 * HALF_WIDTH + 1)
    # The neighbours without the sample itself: an outlier must not pull its own median.
    neighbours = np.delete(windows, HALF_WIDTH, axis=1)
    if not np.isnan(values).any():  # numpy's median is several times faster than nanmedian
        return np.asarray(np.abs(values - np.median(neighbours, axis=1)))
    with np.errstate(all='ignore'), warnings.catch_warnings():
        warnings.simplefilter('ignore', RuntimeWarning)  # all neighbours NaN: NaN
        return np.asarray(np.abs(values - np.nanmedian(neighbours, axis=1)))


def _peaks(departure: np.ndarray) -> np.ndarray:
    """Whether each departure is the largest within ``HALF_WIDTH`` samples either side."""
    padded = np.pad(np.nan_to_num(departure, nan=-1.0), HALF_WIDTH, constant_values=-1.0)
    return np.asarray(departure >= sliding_window_view(padded, 2 * HALF_WIDTH + 1).max(axis=1))


def _even(t: np.ndarray) -> np.ndarray:
    """Whether each sample's neighbours are evenly spaced (no gap, no burst among them)."""
    padded = np.pad(t, HALF_WIDTH, mode='edge')
    windows = sliding_window_view(padded, 2 * HALF_WIDTH + 1)
    span = windows[:, -1] - windows[:, 0]
    step = float(np.median(np.diff(t))) if t.size > 1 else 0.0
    return np.asarray(span <= SPAN_TOLERANCE * 2 * HALF_WIDTH * step)


def spikes(values: np.ndarray, t: np.ndarray | None = None) -> np.ndarray:
    """Which samples of a series are isolated outliers (the module's rule).

    An outlier also moves the median its neighbours are compared with; only the largest
    departure within ``HALF_WIDTH`` samples is taken in a pass, and a second pass, with it
    bridged by its neighbours, finds an outlier beside it.

    Args:
        values: Values in time order (NaN: never an outlier).
        t: Their stamps, s: a sample whose neighbours span a gap is not judged (their
            median is no prediction of it). ``None``: evenly sampled.

    Returns:
        A boolean mask; all ``False`` for fewer than ``2 * HALF_WIDTH + 1`` samples or when
        more than ``MAX_FRACTION`` would be flagged.
    """
    n = values.size
    flagged = np.zeros(n, dtype=bool)
    if n < 2 * HALF_WIDTH + 1:
        return flagged
    judged = np.ones(n, dtype=bool) if t is None else _even(t)
    departure = _departures(values)
    departure[~judged] = np.nan
    finite = departure[np.isfinite(departure)]
    if finite.size == 0:
        return flagged
    scale = max(
        _MAD_SCALE * float(np.median(finite)), _P90_SCALE * float(np.percentile(finite, 90))
    )
    if scale <= 0.0:
        return flagged
    remaining = values.astype(float, copy=True)
    for _ in range(PASSES):
        found = np.isfinite(departure) & (departure > THRESHOLD * scale) & _peaks(departure)
        if not found.any():
            break
        flagged |= found
        if np.count_nonzero(flagged) > MAX_FRACTION * n:
            return np.zeros(n, dtype=bool)
        # Bridged by its neighbours, an outlier no longer tilts theirs.
        index = np.arange(n)
        good = ~flagged & np.isfinite(remaining)
        remaining[flagged] = np.interp(index[flagged], index[good], remaining[good])
        departure = _departures(remaining)
        departure[~judged] = np.nan
    return flagged


def without_spikes(window: PoseWindow) -> PoseWindow:
    """A window without its isolated outliers of z or pitch, counted as ``outliers``.

    Args:
        window: Cleaned poses (strictly increasing stamps).

    Returns:
        The window itself when it has none, else a copy without them.
    """
    poses = window.poses
    flagged = spikes(poses.z, poses.t) | spikes(poses.pitch, poses.t)
    count = int(np.count_nonzero(flagged))
    if not count:
        return window
    keep = ~flagged
    kept = TipSeries(poses.t[keep], poses.x[keep], poses.z[keep], poses.pitch[keep])
    counts = window.counts.then(SampleCounts(received=window.counts.kept, outliers=count))
    return PoseWindow(kept, window.loads, counts)
