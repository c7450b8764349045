"""Parameter covariances that stay honest when residuals are correlated.

The textbook least-squares covariance ``s^2 (J^T J)^-1`` assumes white residuals. A camera's
pose noise is often smoothed by the tracker, and a model that leaves out a mode or a drift
leaves correlated residuals; both make ``s^2 (J^T J)^-1`` far too small. These helpers use the
Newey-West (Bartlett-weighted) sandwich instead, with a lag long enough to cover the measured
residual correlation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: Lags looked ahead when deciding that the residual autocorrelation has died out.
_LOOKAHEAD = 16
#: Up to this many lags the sandwich's middle is summed directly, beyond it by FFT.
_DIRECT_MAX_LAG = 24


@dataclass(frozen=True)
class Covariance:
    """A parameter covariance with its white-noise counterpart.

    Attributes:
        matrix: The correlation-robust (sandwich) covariance.
        white: ``s^2 (J^T J)^-1``, valid only for white residuals.
        residual_std: ``sqrt(RSS / (N - p))``.
        lag: Number of residual autocovariance lags used.
    """

    matrix: np.ndarray
    white: np.ndarray
    residual_std: float
    lag: int

    @property
    def inflation(self) -> float:
        """How much the robust variances exceed the white ones (geometric mean over params)."""
        ratio = np.diag(self.matrix) / np.maximum(np.diag(self.white), 1e-300)
        return float(np.exp(np.mean(np.log(np.maximum(ratio, 1e-300)))))


def autocorrelation(residuals: np.ndarray, max_lag: int) -> np.ndarray:
    """Sample autocovariances ``gamma_0..gamma_max_lag`` (biased, divided by N), via the FFT.

    Args:
        residuals: Zero-mean residuals.
        max_lag: Largest lag wanted.

    Returns:
        Array of ``max_lag + 1`` autocovariances.
    """
    n = residuals.size
    size = 1 << int(np.ceil(np.log2(max(2 * n - 1, 2))))
    spectrum = np.fft.rfft(residuals, size)
    gamma = np.fft.irfft(spectrum * np.conj(spectrum), size)[: max_lag + 1]
    return gamma / n


def choose_lag(residuals: np.ndarray) -> int:
    """The Bartlett bandwidth: the Newey-West rule or twice the residual correlation length.

    The correlation length is the first lag from which the autocorrelation stays, over the
    next :data:`_LOOKAHEAD` lags, within 2.5 Bartlett standard errors
    ``sqrt((1 + 2 sum_{j<k} rho_j^2) / N)`` of zero. Looking ahead keeps an oscillating
    autocorrelation (an unfitted mode) from ending at its first zero crossing.

    Args:
        residuals: Fit residuals.

    Returns:
        The number of lags, at least 1 and at most N/4.
    """
    return _lag_and_autocovariance(residuals)[0]


def _lag_and_autocovariance(residuals: np.ndarray) -> tuple[int, np.ndarray]:
    """:func:`choose_lag` and the autocovariances up to N/4 it was chosen from."""
    n = residuals.size
    rule = int(4.0 * (n / 100.0) ** (2.0 / 9.0))
    limit = max(1, n // 4)
    gamma = autocorrelation(residuals - residuals.mean(), limit)
    if gamma[0] <= 0.0 or limit < 2:
        return max(1, min(rule, limit)), gamma
    rho = np.abs(gamma[1:] / gamma[0])
    se = np.sqrt((1.0 + 2.0 * np.concatenate([[0.0], np.cumsum(rho[:-1] ** 2)])) / n)
    ahead = np.lib.stride_tricks.sliding_window_view(
        np.concatenate([rho, np.zeros(_LOOKAHEAD - 1)]), _LOOKAHEAD
    ).max(axis=1)
    quiet = np.flatnonzero(ahead < 2.5 * se)
    length = int(quiet[0]) if quiet.size else limit
    return int(np.clip(max(rule, 2 * length), 1, limit)), gamma


def sandwich_covariance(
    jacobian: np.ndarray, residuals: np.ndarray, prior: np.ndarray | None = None
) -> Covariance:
    """Newey-West covariance of least-squares parameters.

    ``cov = (J^T J)^-1 M (J^T J)^-1`` with ``M = sum_k w_k gamma_k C_k`` over lags
    ``|k| <= lag``, Bartlett weights ``w_k = 1 - |k| / (lag + 1)``, residual autocovariances
    ``gamma_k`` and ``C_k = sum_i J_i J_{i+k}^T``. For white residuals it equals
    ``s^2 (J^T J)^-1`` up to sampling noise.

    A prior enters as rows ``G`` of observations weighed to the residuals' variance
    ``s^2``, independent of the data: ``(J^T J + G^T G)^-1 (M + s^2 G^T G) (J^T J + G^T G)^-1``.

    Args:
        jacobian: N x p Jacobian of the model at the solution.
        residuals: N residuals at the solution.
        prior: The prior's weighted gradient rows (k x p), if any.

    Returns:
        The covariance.
    """
    n, p = jacobian.shape
    dof = max(n - p, 1)
    s2 = float(residuals @ residuals) / dof
    information = jacobian.T @ jacobian
    if prior is not None:
        information = information + prior.T @ prior
    bread = np.linalg.pinv(information)
    white = s2 * bread
    lag, gamma = _lag_and_autocovariance(residuals)
    kernel = _bartlett(lag) * gamma[: lag + 1] * (n / dof)
    if lag <= _DIRECT_MAX_LAG:
        # sum_k w_k gamma_k (C_k + C_k^T): a few small products beat the FFT's set-up.
        meat = kernel[0] * (jacobian.T @ jacobian)
        for k in range(1, lag + 1):
            cross = jacobian[:-k].T @ jacobian[k:]
            meat += kernel[k] * (cross + cross.T)
    else:
        # J^T Sigma J with Sigma the Toeplitz matrix of the tapered autocovariances: Sigma J
        # is a convolution of each Jacobian column with the kernel, O(N log N), not O(N lag).
        kernel = np.concatenate([kernel[:0:-1], kernel])
        meat = jacobian.T @ _convolve_same(jacobian, kernel)
    if prior is not None:
        meat = meat + s2 * (prior.T @ prior)
    matrix = bread @ meat @ bread
    # Bartlett-tapered biased autocovariances form a positive semi-definite Toeplitz matrix
    # (a Schur product of two), so the meat, and the result, are too; only rounding remains.
    matrix = 0.5 * (matrix + matrix.T)
    return Covariance(matrix, white, float(np.sqrt(s2)), lag)


def _convolve_same(columns: np.ndarray, kernel: np.ndarray) -> np.ndarray:
    """Each column convolved with an odd-length kernel, centred (``mode='same'``), by FFT.

    numpy's FFT rather than ``scipy.signal.fftconvolve``: importing scipy.signal takes
    longer than a whole identification (``lumpbeam analyze`` starts in a fraction of it).

    Args:
        columns: Shape (N, m).
        kernel: Shape (K,), K odd.

    Returns:
        Shape (N, m): the full convolution's middle N rows.
    """
    n, k = columns.shape[0], kernel.size
    size = n + k - 1
    fast = 1 << (size - 1).bit_length()
    spectrum = np.fft.rfft(columns, fast, axis=0) * np.fft.rfft(kernel, fast)[:, None]
    full = np.fft.irfft(spectrum, fast, axis=0)
    start = (k - 1) // 2
    return np.asarray(full[start : start + n])


def mean_with_std(values: np.ndarray) -> tuple[float, float]:
    """Mean of a stationary series and its standard error, allowing for autocorrelation.

    The variance of the mean is the Bartlett long-run variance over N,
    ``sum_{|k|<=lag} w_k gamma_k / N`` (the sandwich with a column of ones).

    Args:
        values: The series (at least 2 samples).

    Returns:
        The mean and its standard deviation (NaN for fewer than 2 samples).
    """
    if values.size < 2:
        return (float(values.mean()) if values.size else float('nan')), float('nan')
    n = values.size
    mean = float(values.mean())
    lag, gamma = _lag_and_autocovariance(values - mean)
    weights = _bartlett(lag)
    long_run = gamma[0] + 2.0 * float(weights[1:] @ gamma[1 : lag + 1])
    return mean, float(np.sqrt(max(long_run, 0.0) * n / (n - 1) / n))


def _bartlett(lag: int) -> np.ndarray:
    """Bartlett weights ``1 - k / (lag + 1)`` for k = 0..lag."""
    return 1.0 - np.arange(lag + 1) / (lag + 1.0)


def propagate(gradient: np.ndarray, covariance: np.ndarray) -> float:
    """Standard deviation of a function of parameters by first-order propagation.

    Args:
        gradient: The function's gradient with respect to the parameters.
        covariance: The parameters' covariance.

    Returns:
        ``sqrt(g^T C g)``.
    """
    return float(np.sqrt(max(float(gradient @ covariance @ gradient), 0.0)))
