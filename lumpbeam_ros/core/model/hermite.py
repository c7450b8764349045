"""Cubic Hermite interpolation of a solved trajectory from its values and derivatives.

Between grid points ``t_i`` and ``t_{i+1}`` (``h`` apart, ``s = (t - t_i) / h``) the cubic
that matches the angles and rates at both ends:

    y(t) = h00(s) y_i + h h10(s) y'_i + h01(s) y_{i+1} + h h11(s) y'_{i+1},

with ``h00 = 2s^3 - 3s^2 + 1``, ``h10 = s^3 - 2s^2 + s``, ``h01 = -2s^3 + 3s^2`` and
``h11 = s^3 - s^2``; fourth-order accurate, as ``scipy.interpolate.CubicHermiteSpline``.
Only the intervals asked for are evaluated (building scipy's spline over a whole grid cost
as much as an arm's ring-down sweeps), and scipy.interpolate is not imported (about a third
of ``lumpbeam analyze``'s start-up).
"""

from __future__ import annotations

import numpy as np


def hermite(
    t: np.ndarray, y: np.ndarray, dy: np.ndarray, t_out: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Values and derivatives at ``t_out`` of the cubic Hermite interpolant of ``(t, y, y')``.

    Args:
        t: Increasing grid, at least two points, s.
        y: Values on the grid, one row per point.
        dy: Their time derivatives, same shape.
        t_out: Where to evaluate (outside the grid the end cubics extrapolate).

    Returns:
        ``y(t_out)`` and ``y'(t_out)``, one row per time.
    """
    t_out = np.asarray(t_out, dtype=float)
    i = np.clip(np.searchsorted(t, t_out, side='right') - 1, 0, t.size - 2)
    h = (t[i + 1] - t[i])[:, None]
    s = (t_out - t[i])[:, None] / h
    s2, s3 = s * s, s * s * s
    y0, y1, d0, d1 = y[i], y[i + 1], dy[i], dy[i + 1]
    value = (
        (2.0 * s3 - 3.0 * s2 + 1.0) * y0
        + h * (s3 - 2.0 * s2 + s) * d0
        + (3.0 * s2 - 2.0 * s3) * y1
        + h * (s3 - s2) * d1
    )
    rate = (
        (6.0 * (s2 - s) / h) * (y0 - y1)
        + (3.0 * s2 - 4.0 * s + 1.0) * d0
        + (3.0 * s2 - 2.0 * s) * d1
    )
    return value, rate
