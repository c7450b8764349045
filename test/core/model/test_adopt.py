import math
from dataclasses import replace

import pytest

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model.adopt import adopt_identified, first_mode
from lumpbeam_ros.core.model.parameters import BeamParameters

BEAM = BeamParameters()


@pytest.mark.parametrize('zeta', [0.0005, 0.0024, 0.02])
@pytest.mark.parametrize(
    'start', [BEAM, replace(BEAM, c_total=0.0), replace(BEAM, stiffness_source='analytic')]
)
def test_adopted_beam_has_the_identified_damping_ratio(zeta, start):
    beam = adopt_identified(start, 3500.0, zeta)
    assert beam.stiffness_source == 'identified'
    assert beam.k_total_nm_per_rad == 3500.0
    assert first_mode(beam)[2] == pytest.approx(zeta, rel=1e-5)


def test_identified_values_of_the_paper_beam_give_it_back():
    f_n, _, zeta = first_mode(BEAM)
    assert f_n == pytest.approx(3.06, abs=0.01)
    beam = adopt_identified(BEAM, BEAM.k_total_nm_per_rad, zeta)
    assert beam.c_total == pytest.approx(BEAM.c_total, rel=1e-6)


def test_zero_damping_ratio_switches_damping_off():
    assert adopt_identified(BEAM, 3000.0, 0.0).c_total == 0.0


@pytest.mark.parametrize(
    ('k', 'zeta', 'message'),
    [
        (-1.0, 0.01, 'stiffness'),
        (math.nan, 0.01, 'stiffness'),
        (3000.0, 1.5, 'damping ratio'),
        (3000.0, math.nan, 'damping ratio'),
        (3000.0, -0.1, 'damping ratio'),
        # Once fed to an adopting simulator, each of these stopped it.
        (1.0, 0.01, 'not within a factor of 10 of the beam'),
        (1e-300, 0.01, 'not within a factor of 10'),
        (8.6e302, 0.01, 'not within a factor of 10'),
    ],
)
def test_rejects_impossible_estimates(k, zeta, message):
    with pytest.raises(LumpbeamError, match=message):
        adopt_identified(BEAM, k, zeta)


def test_rejects_damping_without_beta():
    with pytest.raises(LumpbeamError, match='beta'):
        adopt_identified(replace(BEAM, beta_identified=0.0), 3000.0, 0.01)


@pytest.mark.parametrize('factor', [0.1, 10.0])
def test_a_stiffness_up_to_ten_times_the_beams_either_way_is_adopted(factor):
    own = BEAM.segment_stiffness() / BEAM.n_segments
    assert adopt_identified(BEAM, factor * own, 0.01).k_total_nm_per_rad == factor * own
