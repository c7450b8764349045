"""Stiffness from static changes and from a frequency, against Euler-Bernoulli cantilevers."""

import math

import pytest

from lumpbeam_ros.core.ident.stiffness import (
    RAYLEIGH_BEAM_FRACTION,
    formula_share,
    from_frequency,
    from_pitch_change,
    from_static_change,
)
from lumpbeam_ros.core.model.parameters import BeamParameters
from lumpbeam_ros.core.model.statics import static_tip_deflection

G = 9.81
CASES = [(5000.6, 2.3107, 4.5), (1200.0, 1.0, 0.5), (20000.0, 3.0, 10.0)]  # EI, L, load


@pytest.mark.parametrize(('ei', 'length', 'load'), CASES)
def test_static_deflection_gives_two_ei_over_l(ei, length, load):
    force = load * G
    deflection = force * length**3 / (3.0 * ei)  # end-loaded cantilever
    found = from_static_change(deflection, 0.01 * deflection, load, length, G)
    # B.12 on an Euler-Bernoulli beam: k_tE = 2 F L^2 / (3 delta) = 2 EI / L.
    assert found.total_nm_per_rad == pytest.approx(2.0 * ei / length)
    assert found.vertical_n_per_m == pytest.approx(3.0 * ei / length**3)
    assert found.total_nm_per_rad_std == pytest.approx(0.01 * found.total_nm_per_rad)
    assert found.vertical_n_per_m_std == pytest.approx(0.01 * found.vertical_n_per_m)


@pytest.mark.parametrize(('ei', 'length', 'load'), CASES)
def test_slope_form_agrees_with_the_deflection_form(ei, length, load):
    force = load * G
    slope = force * length**2 / (2.0 * ei)  # end-loaded cantilever
    total, std = from_pitch_change(slope, 0.02 * slope, load, length, G)
    assert total == pytest.approx(2.0 * ei / length)
    assert std == pytest.approx(0.02 * total)


@pytest.mark.parametrize(
    ('change', 'load'), [(0.0, 4.5), (-1e-3, 4.5), (math.nan, 4.5), (1e-3, 0.0)]
)
def test_no_stiffness_without_a_positive_change_and_load(change, load):
    static = from_static_change(change, 1e-6, load, 2.0, G)
    assert math.isnan(static.total_nm_per_rad) and math.isnan(static.vertical_n_per_m_std)
    assert all(math.isnan(v) for v in from_pitch_change(change, 1e-6, load, 2.0, G))


@pytest.mark.parametrize(('ei', 'length', 'tip_kg', 'beam_kg'), [(5000.6, 2.3107, 0.8, 1.9)])
def test_frequency_gives_the_rayleigh_stiffness(ei, length, tip_kg, beam_kg):
    k = 3.0 * ei / length**3
    # Rayleigh's first frequency of a cantilever with a tip mass (33/140 of the beam moves).
    f = math.sqrt(k / (tip_kg + 33.0 / 140.0 * beam_kg)) / (2 * math.pi)
    found, std = from_frequency(f, 1e-3, tip_kg, beam_kg)
    assert found == pytest.approx(k)
    assert RAYLEIGH_BEAM_FRACTION == pytest.approx(0.2357, abs=1e-4)
    # k grows as f^2: its std is the derivative times the frequency's std.
    h = 1e-6
    slope = (
        from_frequency(f + h, 0, tip_kg, beam_kg)[0] - from_frequency(f - h, 0, tip_kg, beam_kg)[0]
    ) / (2 * h)
    assert std == pytest.approx(slope * 1e-3, rel=1e-6)
    assert all(math.isnan(v) for v in from_frequency(math.inf, 0.0, tip_kg, beam_kg))


@pytest.mark.parametrize(('after', 'load'), [(0.0, 4.5), (0.0, 1.0), (2.0, 1.0)])
def test_b12s_own_error_on_the_lumped_beam_is_its_share(after, load):
    """B.12 on the chain's own static change errs by the share it reports, a few tenths of %."""
    beam = BeamParameters()
    share = formula_share(beam, after, load)
    deflection = static_tip_deflection(beam, after + load) - static_tip_deflection(beam, after)
    found = from_static_change(deflection, 0.0, load, beam.length_m, beam.gravity_mps2, share)
    error = found.total_nm_per_rad - beam.k_total_nm_per_rad
    assert 1e-3 < share < 1e-2
    assert abs(error) == pytest.approx(found.total_nm_per_rad_std, rel=0.01)


@pytest.mark.parametrize(('after', 'load'), [(0.0, 0.0), (math.nan, 4.5), (-1.0, 4.5)])
def test_no_share_without_a_release_to_compute_it_on(after, load):
    assert formula_share(BeamParameters(), after, load) == 0.0
