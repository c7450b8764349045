from dataclasses import replace

import numpy as np
import pytest

from lumpbeam_ros.core.model.chain import LumpedChain
from lumpbeam_ros.core.model.modes import chain_modes
from lumpbeam_ros.core.model.parameters import BeamParameters


def test_single_segment_matches_spring_pendulum():
    beam = BeamParameters(n_segments=1, gravity_mps2=0.0, beta_identified=0.0, tip_mass_kg=2.0)
    modes = chain_modes(LumpedChain.from_beam(beam))
    inertia = beam.mass_kg * beam.length_m**2 / 3 + 2.0 * beam.length_m**2
    expected = np.sqrt(beam.segment_stiffness() / inertia) / (2 * np.pi)
    assert modes.natural_frequency_hz[0] == pytest.approx(expected, rel=1e-9)
    assert modes.damping_ratio[0] == pytest.approx(0.0, abs=1e-12)


def test_damping_ratio_matches_stiffness_proportional_damping():
    # c = beta k on every joint: each mode's zeta = beta omega / 2.
    beam = replace(BeamParameters(), stiffness_source='analytic', beta_analytic=1e-4)
    beam = replace(beam, gravity_mps2=0.0)
    modes = chain_modes(LumpedChain.from_beam(beam))
    omega = 2 * np.pi * modes.natural_frequency_hz[:3]
    assert modes.damping_ratio[:3] == pytest.approx(1e-4 * omega / 2, rel=1e-6)


@pytest.mark.parametrize(
    ('source', 'mounted', 'placement', 'paper_hz'),
    [
        ('analytic', 2.5, 'segment_com', 3.42),
        ('identified', 2.5, 'segment_com', 3.24),
        ('identified', 4.5, 'segment_com', 2.51),
    ],
)
def test_paper_frequencies(source, mounted, placement, paper_hz):
    beam = replace(
        BeamParameters(), stiffness_source=source, tip_mass_kg=mounted, tip_placement=placement
    )
    f = chain_modes(LumpedChain.from_beam(beam)).damped_frequency_hz[0]
    assert f == pytest.approx(paper_hz, rel=0.01)


def test_mode_shapes_are_normalised():
    modes = chain_modes(LumpedChain.from_beam(BeamParameters()))
    assert np.allclose(np.abs(modes.shapes).max(axis=0), 1.0)
    assert np.all(np.diff(modes.natural_frequency_hz) > 0)
