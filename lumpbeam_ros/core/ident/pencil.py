"""Matrix-pencil estimation of damped modes (Hua and Sarkar, 1990).

An independent cross-check of the least-squares fit and its starting point: it needs no
initial guess, finds several modes at once and gives their frequencies and damping ratios
from the signal subspace of a Hankel matrix. It has no covariance of its own.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.mode_estimate import ModeEstimate


@dataclass(frozen=True)
class PencilResult:
    """Modes found by the pencil, strongest first.

    Attributes:
        modes: Oscillating modes (damped frequency > 0), by decreasing amplitude.
        offset: Amplitude of the non-oscillating pole nearest to z = 1 (the static level).
        sample_rate_hz: Rate of the uniform grid the pencil ran on.
    """

    modes: tuple[ModeEstimate, ...]
    offset: float
    sample_rate_hz: float


class MatrixPencil:
    """Matrix-pencil mode estimator, in a fit shape.

    The samples are put on a uniform grid (linear interpolation over gaps), then averaged in
    blocks of ``decimation`` samples: a block mean is a linear filter, so it scales each
    mode's amplitude but leaves its poles, and it shrinks the SVD.

    Args:
        order: Signal-subspace dimension: 1 for the offset plus 2 per mode, plus spare
            pairs that soak up noise. Default 7 (offset, two modes, one spare).
        pencil_length: Pencil parameter L, the Hankel matrix's column count.
        decimation: Samples averaged per grid point.
    """

    def __init__(self, order: int = 7, pencil_length: int = 40, decimation: int = 1):
        if order < 1 or pencil_length <= order or decimation < 1:
            raise ValueError('need 1 <= order < pencil_length and decimation >= 1')
        self.order = order
        self.pencil_length = pencil_length
        self.decimation = decimation
        self.result_: PencilResult | None = None

    def fit(self, t: np.ndarray, y: np.ndarray) -> PencilResult:
        """Finds the damped modes of a record.

        Args:
            t: Increasing stamps, s (gaps are interpolated).
            y: Samples.

        Returns:
            The modes, also kept as ``self.result_``.

        Raises:
            LumpbeamError: Too few samples for the pencil, or samples too large to centre.
        """
        t = np.asarray(t, dtype=float)
        y = np.asarray(y, dtype=float)
        dt = float(np.median(np.diff(t))) * self.decimation
        u = _uniform_blocks(t, y, self.decimation)
        n = u.size
        length = min(self.pencil_length, n // 3)
        if length <= self.order:
            raise LumpbeamError(f'matrix pencil: {t.size} samples are too few')
        # Centring keeps a large static level from dominating the subspace.
        with np.errstate(over='ignore', invalid='ignore'):  # checked just below
            centre = float(u.mean())
            scale = float(np.max(np.abs(u - centre))) or 1.0
            u = (u - centre) / scale
        if not np.all(np.isfinite(u)):
            # Finite samples near the float limit (1e308) overflow the centring; the SVD below
            # would fail with a bare LinAlgError.
            raise LumpbeamError('matrix pencil: samples too large to centre (near 1e308)')
        # Contiguous, so the Gram product below runs in BLAS.
        hankel = np.ascontiguousarray(np.lib.stride_tricks.sliding_window_view(u, length + 1))
        # The right singular vectors from the small Gram matrix: an (L+1)^2 eigenproblem
        # instead of an SVD of the whole (N-L) x (L+1) Hankel matrix.
        gram = hankel.T @ hankel
        _, vectors = np.linalg.eigh(gram)
        basis = vectors[:, ::-1][:, : self.order]
        poles = np.linalg.eigvals(np.linalg.pinv(basis[:-1]) @ basis[1:])
        # A spurious pole that grows beyond floating point over the record (seen on a spoiled
        # stream) makes the Vandermonde matrix below inf, and LAPACK's least squares on it
        # never returns (a hung identifier); a decaying mode is never such a pole.
        with np.errstate(divide='ignore', invalid='ignore'):
            growth = n * np.log(np.abs(poles))
        poles = poles[(np.abs(poles) > 1e-9) & (growth < 700.0)]
        s = np.log(poles.astype(complex)) / dt
        # Amplitudes by least squares on the Vandermonde matrix of the poles.
        k = np.arange(n)
        vander = np.exp(np.outer(k * dt, s))
        amps, *_ = np.linalg.lstsq(vander, u.astype(complex), rcond=None)
        amps *= scale
        modes: list[tuple[float, ModeEstimate]] = []
        offset = centre
        best_static = math.inf
        t0 = t[0] + 0.5 * (self.decimation - 1) * dt / self.decimation
        for pole, amp in zip(s, amps, strict=True):
            if pole.imag < -1e-9:
                continue  # the conjugate of a mode counted once
            if abs(pole.imag) <= 1e-9:
                if abs(pole.real) < best_static:
                    best_static = abs(pole.real)
                    offset = centre + float(amp.real)
                continue
            # Shift the amplitude's origin from the first grid point to t[0]; its size is
            # only used for ranking, so the block-mean gain is not undone.
            amplitude = 2.0 * abs(amp) * math.exp(-pole.real * (t[0] - t0))
            mode = ModeEstimate.from_parameters(
                amplitude, 0.0, -float(pole.real), float(pole.imag)
            )
            modes.append((amplitude, mode))
        modes.sort(key=lambda item: -item[0])
        result = PencilResult(tuple(m for _, m in modes), offset, 1.0 / dt)
        self.result_ = result
        return result


def _uniform_blocks(t: np.ndarray, y: np.ndarray, decimation: int) -> np.ndarray:
    """Resamples on the median step and averages blocks of ``decimation`` samples."""
    step = float(np.median(np.diff(t)))
    irregular = np.any(np.abs(np.diff(t) - step) > 0.01 * step)
    if irregular:
        grid = np.arange(t[0], t[-1] + 0.5 * step, step)
        y = np.interp(grid, t, y)
    usable = (y.size // decimation) * decimation
    return np.asarray(y[:usable].reshape(-1, decimation).mean(axis=1))
