import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.compare.rigid import (
    check_rotation_observable,
    fit_rigid,
    point_spread,
    skew,
)
from lumpbeam_ros.core.compare.transforms import RigidTransform

RNG = np.random.default_rng(5)


@pytest.mark.parametrize('planar', [False, True])
@pytest.mark.parametrize('angles', [(0.0, 0.0, 0.0), (4.0, -8.0, 100.0), (170.0, 45.0, -120.0)])
def test_kabsch_recovers_the_transform(angles, planar):
    truth = RigidTransform.from_euler_deg(angles, (1.2, -3.0, 0.35))
    source = RNG.normal(size=(40, 3))
    if planar:
        source[:, 1] = 0.0  # the tip's motion plane: still a unique rotation
    fitted = fit_rigid(source, truth.apply(source))
    assert fitted.angle_to(truth) < 1e-10
    assert np.allclose(fitted.translation, truth.translation, atol=1e-12)
    assert np.linalg.det(fitted.rotation) == pytest.approx(1.0)


def test_inverse_and_quaternion():
    transform = RigidTransform.from_euler_deg((10.0, 20.0, 200.0), (1.0, 2.0, 3.0))
    points = RNG.normal(size=(5, 3))
    assert np.allclose(transform.inverse().apply(transform.apply(points)), points)
    quat = transform.quaternion_xyzw()
    assert quat[3] >= 0.0
    assert np.allclose(Rotation.from_quat(quat).as_matrix(), transform.rotation)


def test_skew_is_the_cross_product():
    a, b = RNG.normal(size=(4, 3)), RNG.normal(size=(4, 3))
    assert np.allclose(np.einsum('nij,nj->ni', skew(a), b), np.cross(a, b))


@pytest.mark.parametrize(
    ('shape', 'message'),
    [
        ('still', 'do not move'),
        ('identical', 'do not move'),
        ('line', 'lie on a line'),
        ('curve', None),
    ],
)
def test_rotation_observability(shape, message):
    s = np.linspace(-0.04, 0.04, 2000)
    noise = 15e-6 * RNG.standard_normal((s.size, 3))
    curves = {
        'still': np.zeros((s.size, 3)) + noise,
        'identical': np.tile([1.0, 2.0, 3.0], (s.size, 1)),
        'line': np.column_stack([0.3 * s, s, -0.2 * s]) + noise,
        'curve': np.column_stack([0.26 * s**2, s, np.zeros_like(s)]) + noise,
    }
    spread = point_spread(curves[shape])
    if message is None:
        check_rotation_observable(spread, '/tracker/point')
    else:
        with pytest.raises(LumpbeamError, match=message):
            check_rotation_observable(spread, '/tracker/point')
