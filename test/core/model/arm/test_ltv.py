"""The deflection solver: its scan, rest stays rest, a violent motion refused quietly."""

import warnings

import numpy as np
import pytest
from arm_cases import small_arm

from lumpbeam_ros.core.model.arm.ltv import SERIES_RAD, DeflectionSolver, RigidMotion, _turned
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.statics import arm_equilibrium


def _joint_angles(model):
    return lambda phi: np.diff(phi, axis=-1, prepend=0.0)[..., model.link_starts]


@pytest.mark.parametrize('largest', [SERIES_RAD, 3.0])
def test_the_turned_angles_cosine_and_sine_are_the_functions_own(largest):
    """By the series up to SERIES_RAD, by numpy's beyond (both to the rounding of r + d)."""
    rng = np.random.default_rng(5)
    r = rng.uniform(-4.0, 4.0, size=(50, 6))
    d = rng.uniform(-largest, largest, size=(50, 6))
    c, s = _turned((np.cos(r), np.sin(r)), d)
    assert c == pytest.approx(np.cos(r + d), abs=4e-15)
    assert s == pytest.approx(np.sin(r + d), abs=4e-15)


def test_an_arm_held_at_rest_stays_there():
    model = ArmModel.from_config(small_arm(3))
    q = np.array([0.3, -0.8, 0.5])
    rest = arm_equilibrium(model, q)
    rigid_angles = model.rigid_angles(q)
    steps = 300
    rigid = RigidMotion(
        np.tile(rigid_angles, (steps, 1)), np.zeros((steps, 10)), np.zeros((steps, 10))
    )
    solver = DeflectionSolver(model.chain, _joint_angles(model))
    d, d_dot = solver.solve(rest - rigid_angles, np.zeros(10), rigid, 1e-3, 128)
    assert d == pytest.approx(np.tile(rest - rigid_angles, (steps, 1)), abs=1e-10)
    assert np.abs(d_dot).max() < 1e-8
    assert solver.frames == 1


def test_a_motion_too_violent_for_small_deflections_is_refused_without_warnings():
    model = ArmModel.from_config(small_arm(1))
    steps = 200
    t = np.arange(steps)[:, None] * 1e-3
    # The joint whipped at 1e5 rad/s^2: deflections of radians, beyond any linearization.
    rigid = RigidMotion(5e4 * t**2 * np.ones(4), 1e5 * t * np.ones(4), np.full((steps, 4), 1e5))
    solver = DeflectionSolver(model.chain, _joint_angles(model))
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        assert solver.solve(np.zeros(4), np.zeros(4), rigid, 1e-3, 64) is None
