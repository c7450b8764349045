"""Covariance-driven stochastic subspace identification (SSI-cov), a peer for the benchmarks.

The textbook algorithm of Peeters and De Roeck, "Reference-based stochastic subspace
identification for output-only modal analysis", Mechanical Systems and Signal Processing
13(6), 1999, section 3, for one output: the output correlations ``R_k`` fill a block
Toeplitz matrix ``T = O C`` (observability times reversed controllability); its SVD
truncated to the model order gives ``O = U_n S_n^(1/2)``; the shift invariance of ``O``
gives the state matrix ``A = O_up^+ O_down``, whose eigenvalues ``mu`` are the discrete
poles, ``lambda = ln(mu) / dt``.

pyOMA2, the usual open implementation, does not install here; this one exists only to be
compared with (``lumpbeam bench --only crb``), never in the product.
"""

from __future__ import annotations

import math

import numpy as np


def ssi_cov_modes(
    y: np.ndarray, rate_hz: float, order: int = 6, block_rows: int = 120
) -> list[tuple[float, float]]:
    """The damped modes SSI-cov finds in one output signal.

    Args:
        y: Samples at a constant rate (their mean is removed).
        rate_hz: Sample rate, Hz.
        order: Model order (states); each damped mode takes two.
        block_rows: Block rows ``i`` of the Toeplitz matrix (correlation lags up to ``2 i``).

    Returns:
        ``(natural frequency Hz, damping ratio)`` of each complex pole pair of positive
        damping, by frequency.

    Raises:
        ValueError: Fewer than ``4 block_rows`` samples or an order above ``block_rows``.
    """
    y = np.asarray(y, dtype=float) - float(np.mean(y))
    n = y.size
    if n < 4 * block_rows or not 0 < order <= block_rows:
        raise ValueError(f'SSI-cov: {n} samples, order {order}, {block_rows} block rows')
    # T = Y_f Y_p^T / j (the paper's eq. 9): past and future block rows of the output
    # Hankel matrix over the same j columns, so every lag R_k = T[r, c], k = i + r - c, is a
    # sum over the same j instants. For a free decay (not a stationary response) that keeps
    # each R_k a combination of the system's own poles; a sum over N - k terms would add
    # their mirror images (growing as e^{+sigma k}), which the SVD cannot tell apart.
    columns = n - 2 * block_rows + 1
    hankel = np.lib.stride_tricks.sliding_window_view(y, columns)[: 2 * block_rows]
    toeplitz = hankel[block_rows:] @ hankel[:block_rows].T / columns
    u, s, _ = np.linalg.svd(toeplitz)
    observability = u[:, :order] * np.sqrt(s[:order])
    state, *_ = np.linalg.lstsq(observability[:-1], observability[1:], rcond=None)
    poles = np.log(np.linalg.eigvals(state).astype(complex)) * rate_hz
    modes = []
    for pole in poles:
        if pole.imag > 0.0 and pole.real < 0.0:
            omega = abs(pole)
            modes.append((omega / (2.0 * math.pi), -pole.real / omega))
    return sorted(modes)
