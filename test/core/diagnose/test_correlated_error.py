"""The diagnosis under a camera-like measurement error: smooth, not white, and a bias jump.

A tracker's error follows the target through the image, so it is correlated over many
frames, and after losing the target it may settle on a new constant bias. Differences see
only the small white part; the diagnosis must still name a hidden latency, call nominal
data ``none`` and a hardening clamp ``unexplained``.
"""

import numpy as np
import pytest
from scipy.signal import butter, sosfiltfilt

from lumpbeam_ros.core.diagnose.measurement import Record, make_record
from lumpbeam_ros.core.diagnose.workflow import diagnose
from lumpbeam_ros.core.model.parameters import load_beam_config
from lumpbeam_ros.core.model.trajectory import TipTrajectory
from lumpbeam_ros.core.synthetic.drop_test import (
    PITCH_NOISE_PER_M,
    SynthOptions,
    simulate_experiment,
)

from .hardening import simulate_hardening_drop

WHITE_M = 1e-6
SMOOTH_M = 10e-6
#: The frames lost at the drop (as a blurred board is) and the bias after them.
LOST = slice(396, 409)
BIAS_JUMP_M = 40e-6


def _camera_record(trajectory: TipTrajectory, seed: int, jump: bool) -> Record:
    rng = np.random.default_rng(seed)
    sos = butter(2, 2.0, fs=180.0, output='sos')  # error correlated over ~0.1 s
    smooth = sosfiltfilt(sos, rng.standard_normal((2, len(trajectory))), axis=1)
    error = SMOOTH_M * smooth / smooth.std(axis=1, keepdims=True)
    error += WHITE_M * rng.standard_normal(error.shape)
    z = trajectory.z + error[0]
    pitch = trajectory.pitch + PITCH_NOISE_PER_M * error[1]
    keep = np.ones(len(trajectory), dtype=bool)
    if jump:
        z = z + np.where(np.arange(z.size) >= LOST.stop, BIAS_JUMP_M, 0.0)
        keep[LOST] = False
    return make_record(trajectory.t[keep], z[keep], pitch[keep], 4.5, [(2.0, 0.0)])


@pytest.fixture(scope='module')
def diagnoses():
    beam, drop = load_beam_config()
    late, _ = simulate_experiment(beam, drop, SynthOptions(effects={'sensor_latency': 0.015}))
    nominal, _ = simulate_experiment(beam, drop, SynthOptions())
    hard = simulate_hardening_drop(beam, drop, 5e8)
    cases = {'latency_jump': (late, True), 'nominal': (nominal, False), 'hardening': (hard, False)}
    return {
        label: diagnose(_camera_record(traj, seed, jump), beam)
        for seed, (label, (traj, jump)) in enumerate(cases.items())
    }


def test_the_error_floor_includes_the_smooth_part(diagnoses):
    # Differences alone see about the white micrometre; the floor sees most of the 10 um.
    assert diagnoses['nominal'].noise_z_m == pytest.approx(SMOOTH_M, rel=0.3)


def test_a_hidden_latency_is_named_through_smooth_error_and_a_bias_jump(diagnoses):
    d = diagnoses['latency_jump']
    assert d.missing_effect == 'sensor_latency', d.decision.reason
    assert d.effect_parameters['latency_s'] == pytest.approx(0.015, rel=0.05)
    assert d.gap_after.rms_m <= 0.05 * d.gap_before.rms_m


def test_nominal_data_with_smooth_error_gets_none(diagnoses):
    d = diagnoses['nominal']
    assert d.missing_effect == 'none', d.decision.reason
    assert d.nominal.record_chi2 < 1.5


def test_a_hardening_clamp_stays_unexplained_under_smooth_error(diagnoses):
    d = diagnoses['hardening']
    assert d.missing_effect == 'unexplained', d.decision.reason
    assert min(s.record_chi2 for s in d.candidates) > 1.5
