"""Each link's stiffness and damping from modes: truth recovered, stds that hold, refusals.

The measured modes come from a truth arm (the test arms, and MuJoCo's own linearization of
it), the fit starts from a nominal arm whose stiffnesses are 20 % off.
"""

from dataclasses import replace

import numpy as np
import pytest
from arm_cases import FINALS, observe_modes, small_arm

from lumpbeam_lab.mujoco_arm import MujocoArm
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.arm.link_fit import (
    FREQUENCY_FLOOR,
    LinkParameterFit,
    MeasuredMode,
    ModeObservation,
    link_stiffness_total,
    match_modes,
    scaled_arm,
)
from lumpbeam_ros.core.model.arm.config import arm_from_mapping
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.statics import arm_modes

TRUTH = small_arm(3)


def nominal_of(truth, factors=(0.8, 1.2, 0.8), beta_factor=1.3):
    """The truth with its stiffnesses off by ``factors`` and its dampings by ``beta_factor``."""
    n = truth.n_joints
    betas = np.array([link.damping_beta * beta_factor for link in truth.links])
    return scaled_arm(truth, np.array(factors[:n]), betas)


def truth_values(truth):
    return np.array([[link_stiffness_total(link), link.damping_beta] for link in truth.links]).T


def fitted_values(fit):
    return np.array([[e.k_total_nm_per_rad, e.damping_beta] for e in fit.links]).T


def fitted_stds(fit):
    return np.array([[e.k_total_nm_per_rad_std, e.damping_beta_std] for e in fit.links]).T


@pytest.fixture(scope='module')
def exact_fit():
    return LinkParameterFit(nominal_of(TRUTH)).fit(observe_modes(TRUTH, FINALS[:3], 3))


def test_exact_modes_give_the_truth_back_from_20_percent_off(exact_fit):
    assert fitted_values(exact_fit) == pytest.approx(truth_values(TRUTH), rel=1e-6)
    assert exact_fit.chi2 < 1e-8
    assert exact_fit.dof == 3 * 3 * 2 - 6
    assert exact_fit.matches == ((0, 1, 2),) * 3


def test_the_fitted_arm_predicts_the_truths_modes_elsewhere(exact_fit):
    q = np.array(FINALS[3])
    want = arm_modes(ArmModel.from_config(TRUTH), q).natural_frequency_hz[:3]
    assert exact_fit.predict(q).natural_frequency_hz[:3] == pytest.approx(want, rel=1e-7)


def test_noisy_modes_give_the_truth_within_3_std_and_5_percent():
    rng = np.random.default_rng(4)
    fit = LinkParameterFit(nominal_of(TRUTH)).fit(observe_modes(TRUTH, FINALS, 3, rng))
    truth, got, std = truth_values(TRUTH), fitted_values(fit), fitted_stds(fit)
    assert np.all(np.abs(got[0] - truth[0]) < 3 * std[0])
    assert np.all(np.abs(got[0] / truth[0] - 1) < 0.05)
    assert np.all(np.abs(got[1] - truth[1]) < 3.5 * std[1])
    # The stds are those the measurement stds imply: a few percent, not inflated.
    assert np.all(std[0] / truth[0] < 0.03)


def test_an_ei_list_link_is_scaled_whole_and_reports_its_first_spring():
    link = TRUTH.links[1]
    assert link.ei_nm2 == (400.0, 300.0, 200.0)
    assert link_stiffness_total(link) == pytest.approx(2 * 400.0 / (0.7 / 3) / 3)
    scaled = scaled_arm(TRUTH, np.array([1.0, 1.5, 1.0]), np.zeros(3)).links[1]
    assert scaled.ei_nm2 == pytest.approx((600.0, 450.0, 300.0))
    assert scaled.spring_stiffness() == pytest.approx(1.5 * link.spring_stiffness())


def test_a_mode_missing_from_a_bag_is_matched_past():
    measured = np.array([2.0, 19.0])
    assert match_modes(measured, np.array([2.1, 9.0, 18.0, 57.0])) == (0, 2)
    assert match_modes(np.array([2.0, 2.2]), np.array([2.1, 9.0])) == (0, 1)
    assert match_modes(np.array([1.0, 2.0, 3.0]), np.array([1.0, 2.0])) is None


def test_a_bag_missing_its_second_mode_still_fits():
    obs = observe_modes(TRUTH, FINALS[:3], 3)
    first = obs[0]
    obs[0] = ModeObservation(first.joint_angles_rad, (first.modes[0], first.modes[2]), 'gap')
    fit = LinkParameterFit(nominal_of(TRUTH)).fit(obs)
    assert fit.matches[0] == (0, 2)
    assert fitted_values(fit) == pytest.approx(truth_values(TRUTH), rel=1e-6)


def test_one_link_needs_one_bag_and_a_link_without_damping_starts_from_the_data():
    truth = small_arm(1)
    nominal = scaled_arm(truth, np.array([0.8]), np.array([0.0]))
    fit = LinkParameterFit(nominal).fit(observe_modes(truth, [[0.4]], 1))
    assert fitted_values(fit) == pytest.approx(truth_values(truth), rel=1e-6)
    assert fit.dof == 0 and fit.std_scale == 1.0


def test_modes_from_mujoco_give_the_truth_back():
    truth = small_arm(2)
    finals = ([0.5, -0.9], [-0.3, 0.8], [0.9, 0.3])

    def mujoco_modes(q):
        arm = MujocoArm(truth)
        arm.equilibrium(q)
        lam = arm.modal_eigenvalues()
        lam = lam[lam.imag > 1e-6 * np.abs(lam).max()]
        lam = lam[np.argsort(np.abs(lam))]
        return np.abs(lam) / (2 * np.pi), -lam.real / np.abs(lam)

    obs = observe_modes(truth, finals, 2, modes_at=mujoco_modes)
    fit = LinkParameterFit(nominal_of(truth)).fit(obs)
    assert fitted_values(fit) == pytest.approx(truth_values(truth), rel=1e-5)


def test_a_link_the_data_hardly_see_is_reported_uncertain():
    # The first mode alone at three configurations: the wrist's stiffness barely shows.
    fit = LinkParameterFit(nominal_of(TRUTH)).fit(observe_modes(TRUTH, FINALS, 1))
    warnings = fit.warnings()
    assert any(line.startswith("link 3's stiffness is uncertain by") for line in warnings)
    three = LinkParameterFit(nominal_of(TRUTH)).fit(observe_modes(TRUTH, FINALS[:3], 3)).warnings()
    assert not any('stiffness' in line for line in three)


def test_damping_ratios_measured_too_loosely_are_reported_with_what_to_record(exact_fit):
    # At 5 % x k of each damping ratio, three configurations leave the outer links' damping
    # uncertain by more than 5 %; ring-downs ten times as precise pin it down.
    loose = exact_fit.warnings()
    assert any(line.startswith("link 2's damping is uncertain by") for line in loose)
    assert all('short quick step of the outer joint' in line for line in loose)
    precise = [
        ModeObservation(
            o.joint_angles_rad,
            tuple(replace(m, damping_ratio_std=m.damping_ratio_std / 10) for m in o.modes),
        )
        for o in observe_modes(TRUTH, FINALS[:3], 3)
    ]
    assert LinkParameterFit(nominal_of(TRUTH)).fit(precise).warnings() == []


def test_too_few_modes_for_the_links_is_refused_in_one_line():
    with pytest.raises(LumpbeamError, match=r'1 bag\(s\) give 2 mode\(s\).*at least 3') as err:
        LinkParameterFit(nominal_of(TRUTH)).fit(observe_modes(TRUTH, FINALS[:1], 2))
    assert '\n' not in str(err.value)


def test_configurations_too_alike_leave_a_link_undetermined():
    # Two bags ending at the same angles give the first mode twice: two measurements of
    # one frequency cannot separate two links' stiffnesses.
    truth = small_arm(2)
    obs = observe_modes(truth, [FINALS[0][:2], FINALS[0][:2]], 1)
    with pytest.raises(LumpbeamError, match='do not determine link'):
        LinkParameterFit(nominal_of(truth)).fit(obs)


@pytest.mark.parametrize(
    ('mode', 'message'),
    [
        (MeasuredMode(0.0, 0.01, 0.01, 0.001), 'not positive'),
        (MeasuredMode(float('nan'), 0.01, 0.01, 0.001), 'not positive'),
        (MeasuredMode(2.0, 0.01, 1.0, 0.001), r'outside \[0, 1\)'),
        (MeasuredMode(2.0, 0.01, -0.1, 0.001), r'outside \[0, 1\)'),
        (MeasuredMode(2.0, 0.0, 0.01, 0.001), 'natural_frequency_hz_std'),
        (MeasuredMode(2.0, 0.01, 0.01, float('inf')), 'damping_ratio_std'),
    ],
)
def test_a_bad_measured_mode_is_refused(mode, message):
    obs = [ModeObservation(np.zeros(1), (mode,), 'bag_a')]
    with pytest.raises(LumpbeamError, match=f'bag_a: mode 1: .*{message}'):
        LinkParameterFit(small_arm(1)).fit(obs)


def test_angles_for_another_arm_and_empty_input_are_refused():
    fit = LinkParameterFit(small_arm(2))
    mode = MeasuredMode(2.0, 0.01, 0.01, 0.001)
    with pytest.raises(LumpbeamError, match='bag_b: final joint angles: the arm has 2 joints'):
        fit.fit([ModeObservation(np.zeros(3), (mode,) * 3, 'bag_b')])
    with pytest.raises(LumpbeamError, match='no measured modes'):
        fit.fit([])
    with pytest.raises(LumpbeamError, match='bag_c: no mode measured'):
        fit.fit([ModeObservation(np.zeros(2), (), 'bag_c')])
    with pytest.raises(LumpbeamError, match='predict before fit'):
        fit.predict(np.zeros(2))


def test_more_modes_than_the_model_has_is_refused():
    arm = arm_from_mapping(
        {'arm': {'links': [{'length_m': 1.0, 'n_segments': 1, 'ei_nm2': 100.0, 'mass_kg': 1.0}]}},
        'one',
    )
    mode = MeasuredMode(2.0, 0.01, 0.01, 0.001)
    with pytest.raises(LumpbeamError, match='2 modes measured, more than the arm model has'):
        LinkParameterFit(arm).fit([ModeObservation(np.zeros(1), (mode, mode), 'bag_d')])


def test_a_mode_from_the_json_of_analyze():
    entry = {
        'natural_frequency_hz': 2.0,
        'natural_frequency_hz_std': 0.01,
        'damping_ratio': 0.02,
        'damping_ratio_std': 0.001,
        'amplitude_m': 0.004,
    }
    assert MeasuredMode.from_json(entry, 'bag') == MeasuredMode(2.0, 0.01, 0.02, 0.001)
    with pytest.raises(LumpbeamError, match='bag: mode 2: damping_ratio_std is None, not a'):
        MeasuredMode.from_json({**entry, 'damping_ratio_std': None}, 'bag: mode 2')
    with pytest.raises(LumpbeamError, match='natural_frequency_hz is None'):
        MeasuredMode.from_json({}, 'bag')


def test_a_frequency_measured_finer_than_the_model_matches_is_held_to_the_floor():
    # A first mode reported to 1e-9 claims no stiffness tighter than the linearized model's
    # own 1e-5: the std stays at the floor's size, and an error of a few floors is covered.
    one = small_arm(1)
    (obs,) = observe_modes(one, [[0.4]], 2)
    fine = [replace(m, natural_frequency_hz_std=1e-9 * m.natural_frequency_hz) for m in obs.modes]
    off = replace(fine[0], natural_frequency_hz=fine[0].natural_frequency_hz * (1 + 2e-5))
    fit = LinkParameterFit(nominal_of(one)).fit([replace(obs, modes=(off, fine[1]))])
    (link,) = fit.links
    truth = link_stiffness_total(one.links[0])
    relative = link.k_total_nm_per_rad_std / link.k_total_nm_per_rad
    assert FREQUENCY_FLOOR < relative < 5 * FREQUENCY_FLOOR
    assert abs(link.k_total_nm_per_rad - truth) < 3 * link.k_total_nm_per_rad_std
