"""The payload from modes measured after moves: its value, a std that holds, what is refused."""

from dataclasses import replace

import numpy as np
import pytest
from arm_cases import FINALS, observe_modes, small_arm

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.arm.link_fit import MeasuredMode, scaled_arm
from lumpbeam_ros.core.ident.arm.payload_fit import (
    UNDETERMINED_ABOVE,
    PayloadFit,
    moving_mass_kg,
)


def _finals(n_links, count=3):
    return [q[:n_links] for q in FINALS[:count]]


@pytest.mark.parametrize('n_links', [1, 2, 3])
@pytest.mark.parametrize('file_payload', [0.0, 2.0], ids=['file empty', 'file heavy'])
def test_exact_modes_give_the_payload_back_from_any_start(n_links, file_payload):
    truth = small_arm(n_links)
    observations = observe_modes(truth, _finals(n_links), n_links)
    fit = PayloadFit(truth.with_payload(file_payload)).fit(observations)
    assert fit.payload_kg == pytest.approx(truth.payload_kg, rel=1e-6)
    assert fit.arm.payload_kg == fit.payload_kg
    assert fit.chi2 < 1e-6 and fit.warnings() == []
    assert set(fit.as_json()) >= {'payload_kg', 'payload_kg_std'}


def test_the_std_holds_over_noisy_measurements():
    truth = small_arm(2)
    rng = np.random.default_rng(3)
    z = []
    for _ in range(40):
        fit = PayloadFit(truth.with_payload(0.0)).fit(observe_modes(truth, _finals(2), 2, rng))
        z.append((fit.payload_kg - truth.payload_kg) / fit.payload_kg_std)
    z = np.asarray(z)
    # 40 draws: the z-scores' spread is 1 within about 0.25, their mean 0 within 0.5.
    assert 0.7 < np.std(z) < 1.3 and abs(np.mean(z)) < 0.5
    assert np.mean(np.abs(z) < 2.0) >= 0.85


def test_no_payload_is_found_as_zero():
    truth = small_arm(2).with_payload(0.0)
    fit = PayloadFit(truth.with_payload(1.0)).fit(observe_modes(truth, _finals(2), 2))
    assert fit.payload_kg == pytest.approx(0.0, abs=1e-6)


def test_a_payload_the_modes_ask_to_be_negative_is_refused():
    truth = small_arm(2).with_payload(0.0)
    # The file's links 20 % softer than the arm's: the arm rings faster than any payload lets it.
    soft = scaled_arm(truth, np.array([0.8, 0.8]), np.array([1e-3, 1.5e-3]))
    with pytest.raises(LumpbeamError, match=r'ask for a negative payload \(-') as info:
        PayloadFit(soft).fit(observe_modes(truth, _finals(2), 2))
    assert 'fit the links first' in str(info.value) and '\n' not in str(info.value)


def test_modes_measured_too_loosely_do_not_determine_the_payload():
    truth = small_arm(1)
    (obs,) = observe_modes(truth, [[0.4]], 1)
    loose = MeasuredMode(obs.modes[0].natural_frequency_hz, 1.0, 0.02, 0.5)
    with pytest.raises(LumpbeamError, match='do not determine the payload') as info:
        PayloadFit(truth).fit([replace(obs, modes=(loose,))])
    assert f'{100 * UNDETERMINED_ABOVE:.0f} %' in str(info.value)


def test_bad_observations_are_refused_in_one_line():
    truth = small_arm(2)
    with pytest.raises(LumpbeamError, match='payload fit: no measured modes'):
        PayloadFit(truth).fit([])
    (obs,) = observe_modes(truth, _finals(2, 1), 2)
    with pytest.raises(LumpbeamError, match='final joint angles'):
        PayloadFit(truth).fit([replace(obs, joint_angles_rad=np.zeros(3))])


def test_the_moving_mass_leaves_out_joint_1s_mass():
    arm = small_arm(3)
    links = sum(link.mass_kg for link in arm.links)
    assert moving_mass_kg(arm) == pytest.approx(links + 0.8 + 0.4)
