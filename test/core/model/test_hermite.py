"""The Hermite interpolant against scipy's and against a cubic it must reproduce exactly."""

import numpy as np
import pytest
from scipy.interpolate import CubicHermiteSpline

from lumpbeam_ros.core.model.hermite import hermite


@pytest.mark.parametrize('uneven', [False, True])
def test_it_is_scipys_cubic_hermite_spline(uneven):
    rng = np.random.default_rng(0)
    t = np.cumsum(rng.uniform(0.5, 1.5, 40)) if uneven else np.arange(40) / 180.0
    y, dy = rng.normal(size=(40, 3)), rng.normal(size=(40, 3))
    t_out = np.linspace(t[0] - 0.1 * (t[1] - t[0]), t[-1] + 0.1 * (t[-1] - t[-2]), 333)
    value, rate = hermite(t, y, dy, t_out)
    spline = CubicHermiteSpline(t, y, dy, axis=0)
    np.testing.assert_allclose(value, spline(t_out), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(rate, spline(t_out, 1), rtol=1e-12, atol=1e-10)


def test_a_cubic_is_reproduced_and_the_grid_points_are_hit():
    t = np.array([0.0, 0.3, 1.0, 1.2])
    cubic = np.polynomial.Polynomial([0.5, -1.0, 2.0, 3.0])
    y, dy = cubic(t)[:, None], cubic.deriv()(t)[:, None]
    t_out = np.concatenate([t, np.linspace(0.0, 1.2, 50)])
    value, rate = hermite(t, y, dy, t_out)
    np.testing.assert_allclose(value[:, 0], cubic(t_out), rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(rate[:, 0], cubic.deriv()(t_out), rtol=1e-12, atol=1e-12)
