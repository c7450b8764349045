"""Lines drawn through sampled data: broken where the samples have a gap.

A record with a stretch of lost samples (dropped camera frames) is not to be drawn as a
straight line across the gap: the plot would show a motion that never happened.
"""

from __future__ import annotations

import numpy as np

#: A step longer than this many times the median sample step is a gap.
GAP_STEPS = 3.0


def broken_at_gaps(t: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``t`` and ``y`` with a NaN sample in every gap, so that a line stops there.

    Args:
        t: Sample times, increasing.
        y: The values, one per time.

    Returns:
        The times and values to plot (unchanged when there is no gap).
    """
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    if t.size < 3:
        return t, y
    steps = np.diff(t)
    gaps = np.flatnonzero(steps > GAP_STEPS * float(np.median(steps)))
    if gaps.size == 0:
        return t, y
    middle = (t[gaps] + t[gaps + 1]) / 2.0
    return np.insert(t, gaps + 1, middle), np.insert(y, gaps + 1, np.nan)
