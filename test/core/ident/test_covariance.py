import math

import numpy as np
import pytest

from lumpbeam_ros.core.ident.covariance import (
    autocorrelation,
    choose_lag,
    mean_with_std,
    propagate,
    sandwich_covariance,
)


def test_sandwich_equals_the_direct_lag_sum():
    rng = np.random.default_rng(1)
    jac = rng.normal(size=(400, 3))
    res = np.convolve(rng.normal(size=410), np.ones(6), 'valid')[:400]
    cov = sandwich_covariance(jac, res)
    n, p = jac.shape
    gamma = autocorrelation(res - res.mean(), cov.lag) * n / (n - p)
    meat = gamma[0] * jac.T @ jac
    for k in range(1, cov.lag + 1):
        cross = jac[:-k].T @ jac[k:]
        meat += (1 - k / (cov.lag + 1)) * gamma[k] * (cross + cross.T)
    bread = np.linalg.inv(jac.T @ jac)
    np.testing.assert_allclose(cov.matrix, bread @ meat @ bread, rtol=1e-10)
    assert cov.lag >= 8  # the moving average correlates 5 lags


def test_white_residuals_give_the_textbook_covariance():
    rng = np.random.default_rng(2)
    cov = sandwich_covariance(rng.normal(size=(3000, 2)), rng.normal(size=3000))
    assert cov.inflation == pytest.approx(1.0, abs=0.2)
    assert choose_lag(rng.normal(size=3000)) == int(4 * 30 ** (2 / 9))


@pytest.mark.parametrize('weight', [0.0, 0.5, 3.0])
def test_a_prior_row_adds_its_information(weight):
    # Prior rows are observations of the residuals' variance: with white residuals the
    # covariance is s^2 (J^T J + G^T G)^-1, its diagonal shrinking where the prior bears.
    rng = np.random.default_rng(3)
    jac = rng.normal(size=(3000, 2))
    res = rng.normal(size=3000)
    prior = np.array([[weight * math.sqrt(3000.0), 0.0]])
    cov = sandwich_covariance(jac, res, prior)
    s2 = float(res @ res) / (3000 - 2)
    expected = s2 * np.linalg.inv(jac.T @ jac + prior.T @ prior)
    np.testing.assert_allclose(cov.white, expected, rtol=1e-12)
    np.testing.assert_allclose(np.diag(cov.matrix), np.diag(expected), rtol=0.1)
    alone = sandwich_covariance(jac, res)
    assert cov.matrix[0, 0] == pytest.approx(alone.matrix[0, 0] / (1.0 + weight**2), rel=0.1)
    assert cov.matrix[1, 1] == pytest.approx(alone.matrix[1, 1], rel=0.05)


def test_mean_of_correlated_series_has_a_wider_error():
    rng = np.random.default_rng(3)
    e = rng.normal(size=20000)
    ar = np.empty_like(e)
    ar[0] = e[0]
    for i in range(1, e.size):
        ar[i] = 0.8 * ar[i - 1] + e[i]
    _, std = mean_with_std(ar)
    # Long-run std of an AR(1) mean: sigma_e / (1 - phi) / sqrt(N).
    assert std == pytest.approx(1 / 0.2 / math.sqrt(ar.size), rel=0.2)
    assert math.isnan(mean_with_std(np.array([1.0]))[1])


def test_propagate():
    assert propagate(np.array([1.0, 2.0]), np.diag([4.0, 1.0])) == pytest.approx(math.sqrt(8.0))


def test_the_fft_convolution_is_the_centred_direct_one():
    from lumpbeam_ros.core.ident.covariance import _convolve_same

    rng = np.random.default_rng(3)
    for n, k in ((200, 49), (30, 61), (7, 3)):
        columns, kernel = rng.normal(size=(n, 2)), rng.normal(size=k)
        direct = np.column_stack([np.convolve(c, kernel, mode='full') for c in columns.T])
        start = (k - 1) // 2
        assert _convolve_same(columns, kernel) == pytest.approx(
            direct[start : start + n], abs=1e-12
        )
