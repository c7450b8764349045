import numpy as np
import pytest

from lumpbeam_ros.diagnose.candidates import effect_candidates
from lumpbeam_ros.diagnose.fitting import DIVERGED_RESIDUAL, FitProblem
from lumpbeam_ros.diagnose.record import record_from_trajectory
from lumpbeam_ros.diagnose.selection import Model
from lumpbeam_ros.diagnose.workflow import nominal_form
from lumpbeam_ros.model.parameters import BeamParameters, DropTestConfig
from lumpbeam_ros.model.simulate import simulate_drop_test

BEAM = BeamParameters()


@pytest.fixture(scope='module')
def problem():
    drop = DropTestConfig(release_time_s=0.5, duration_s=2.5)
    record = record_from_trajectory(simulate_drop_test(BEAM, drop), [(0.5, 0.0)], drop.load_kg)
    return FitProblem(record, nominal_form(BEAM), 1e-5, 1e-5)


def test_the_true_model_leaves_no_residual(problem):
    residuals = problem.model_residuals(Model(), np.zeros(2))
    assert residuals.size == 2 * len(problem.record)
    assert np.max(np.abs(residuals)) < 0.1  # well under the 10 um noise


@pytest.mark.parametrize(('name', 'value'), [('base_compliance', 5.0), ('base_compliance', 50.0)])
def test_a_mount_too_soft_to_carry_the_beam_is_a_bad_fit_not_an_error(problem, name, value):
    candidate = next(c for c in effect_candidates(problem.nominal) if c.name == name)
    strength = candidate.reference / value if candidate.reciprocal else value
    residuals = problem.model_residuals(
        Model((candidate,)), np.r_[0.0, 0.0, strength / candidate.scale]
    )
    assert residuals.size == 2 * len(problem.record)
    np.testing.assert_array_equal(residuals, DIVERGED_RESIDUAL)
