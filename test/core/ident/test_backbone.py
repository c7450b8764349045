"""The beam's backbone against MuJoCo's chain, across stiffness, and a beam that cannot drop."""

import math
from dataclasses import replace

import pytest

from lumpbeam_lab.mujoco_arm import mujoco_drop_test
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.backbone import AMPLITUDE_OF_LENGTH, PERIODS, beam_backbone
from lumpbeam_ros.core.ident.sinusoid import DampedSinusoidFit
from lumpbeam_ros.core.model.parameters import BeamParameters
from lumpbeam_ros.core.model.statics import static_tip_deflection

BEAM = BeamParameters()


def test_the_backbone_is_mujocos():
    # MuJoCo's own multibody dynamics of the same chain (relative hinge coordinates, its own
    # mass matrix and gravity), its frequency measured at the same two amplitudes.
    backbone = beam_backbone(BEAM)
    undamped = replace(BEAM, c_total=0.0)
    per_kg = static_tip_deflection(undamped, 1.0) - static_tip_deflection(undamped, 0.0)
    f0 = backbone.natural_frequency_hz
    measured = []
    for fraction in (0.5, 1.0):
        load = fraction * AMPLITUDE_OF_LENGTH * BEAM.length_m / per_kg
        run = mujoco_drop_test(undamped, load, 0.0, PERIODS / f0, 60.0 * f0)
        mode = DampedSinusoidFit().fit(run.t, run.z).mode(0)
        measured.append((mode.natural_frequency_hz, mode.amplitude))
    (f1, a1), (f2, a2) = measured
    gamma = (f2 - f1) / (f0 * (a2 * a2 - a1 * a1))
    assert gamma == pytest.approx(backbone.relative_per_m2, rel=0.003)
    # The shift is the paper beam's: about 7 ppm at the drop's 4 cm.
    assert backbone.relative_per_m2 * 0.04**2 == pytest.approx(7.3e-6, rel=0.05)


@pytest.mark.parametrize('scale', [0.64, 1.5625])
def test_the_relative_backbone_hardly_depends_on_the_stiffness(scale):
    stiffer = replace(BEAM, k_total_nm_per_rad=scale * BEAM.k_total_nm_per_rad)
    found = beam_backbone(stiffer)
    assert found.natural_frequency_hz == pytest.approx(
        math.sqrt(scale) * beam_backbone(BEAM).natural_frequency_hz, rel=0.01
    )
    assert found.relative_per_m2 == pytest.approx(beam_backbone(BEAM).relative_per_m2, rel=0.01)


def test_damping_and_effects_do_not_change_it():
    damped = replace(BEAM, c_total=10 * BEAM.c_total)
    assert beam_backbone(damped).relative_per_m2 == beam_backbone(BEAM).relative_per_m2


def test_a_beam_without_gravity_has_no_drop_to_measure_it_on():
    with pytest.raises(LumpbeamError, match='does not sag'):
        beam_backbone(replace(BEAM, gravity_mps2=0.0))
