"""The one reprojection fit: both pose models succeed, stop and fail the same way."""

import numpy as np
import pytest

from lumpbeam_ros.core.vision.free_pose import FreeModel
from lumpbeam_ros.core.vision.pose import PlaneModel
from lumpbeam_ros.core.vision.reprojection import _symmetric_inverse, fit_pose, sorted_median

PLANE_POSE = np.array([2.3107, -0.012, 0.004])
FREE_POSE = np.array([2.3107, 0.004, -0.012, 0.006, 0.004, -0.008])


def _cases(config):
    return [
        (PlaneModel(config.rig, config.camera_info), PLANE_POSE),
        (FreeModel(config.rig, config.camera_info), FREE_POSE),
    ]


def test_exact_corners_give_the_pose_back_with_no_residual(config):
    for model, pose in _cases(config):
        start = pose + 1e-3
        fit = fit_pose(model, model.project(pose), start)
        assert fit.converged
        np.testing.assert_allclose(fit.pose, pose, atol=1e-9)
        assert fit.rms_px < 1e-6 and fit.covariance.shape == (pose.size, pose.size)
        np.testing.assert_array_equal(start, pose + 1e-3)  # the start is not changed


def test_corners_not_seen_are_left_out(config):
    for model, pose in _cases(config):
        pixels = model.project(pose)
        pixels[::3] = np.nan
        fit = model.fit(pixels, pose + 1e-3)
        assert fit.converged
        np.testing.assert_allclose(fit.pose, pose, atol=1e-9)


@pytest.mark.parametrize('kind', ['too few corners', 'NaN start'])
def test_a_fit_that_cannot_fix_the_pose_is_not_converged_and_raises_nothing(config, kind):
    for model, pose in _cases(config):
        pixels = model.project(pose)
        start = pose.copy()
        if kind == 'too few corners':
            # 2N numbers must exceed the pose's k: one corner for 3, three for 6.
            pixels[pose.size // 2 :] = np.nan
        else:
            start[0] = np.nan
        fit = model.fit(pixels, start)
        assert not fit.converged and np.all(np.isnan(fit.covariance))


class _Flat:
    """A model whose corners do not move with the pose: ``J^T J`` is singular."""

    step_tolerance = 1e-9
    max_iterations = 5

    def __init__(self, k):
        self.k = k

    def project_with_jacobian(self, pose):
        return np.zeros((10, 2)), np.zeros((10, 2, self.k))


@pytest.mark.parametrize('k', [3, 6])
def test_a_singular_fit_is_not_converged_for_either_size(k):
    fit = fit_pose(_Flat(k), np.ones((10, 2)), np.zeros(k))
    assert not fit.converged and np.isnan(fit.rms_px) and fit.covariance.shape == (k, k)


def test_the_cofactor_inverse_is_numpys_and_refuses_a_singular_matrix():
    rng = np.random.default_rng(0)
    a = rng.normal(size=(5, 3))
    m = a.T @ a
    np.testing.assert_allclose(_symmetric_inverse(m), np.linalg.inv(m), rtol=1e-12)
    with pytest.raises(np.linalg.LinAlgError):
        _symmetric_inverse(np.ones((3, 3)))


@pytest.mark.parametrize('n', [1, 2, 7, 48])
def test_sorted_median_is_numpys(n):
    values = np.random.default_rng(n).normal(size=n)
    values[0] = np.inf
    assert sorted_median(values) == np.median(values)
