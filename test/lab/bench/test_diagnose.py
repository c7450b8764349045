import math

import pytest

from lumpbeam_lab.bench import diagnose
from lumpbeam_lab.bench.runner import available_suites


def test_quick_run_diagnoses_the_bag_and_compares_with_radau():
    (result,) = diagnose.run(quick=True)
    assert result.name == 'diagnose_bag_4s_180hz'
    assert result.unit == 's' and result.value > 0 and result.baseline_value > 0
    assert result.ratio == pytest.approx(result.baseline_value / result.value)
    # The timing only means something if the diagnosis is right.
    assert result.details['missing_effect_found'] == 'coulomb_friction'
    assert result.details['torque_nm_found'] == pytest.approx(1.0, rel=0.25)
    # Two seconds after the drop leave the nominal refit close; the effect closes the rest.
    assert result.details['gap_rms_after_um'] < result.details['gap_rms_before_um']
    assert result.details['gap_rms_after_um'] == pytest.approx(20.0, rel=0.15)
    # Both integrators simulate the same beam.
    assert result.details['radau_vs_modal_max_dz_um'] < 1.0
    assert result.details['simulations'] > 50
    assert math.isfinite(result.details['radau_ms_per_simulation_nominal'])
    assert 'diagnose' in available_suites()


@pytest.mark.slow
def test_cpu_row_counts_the_diagnosis_in_simulations_of_the_same_bag():
    row = diagnose.cpu_row({'coulomb_friction': 1.0}, 2.0, 1, 4.0)
    assert row.name == 'diagnose_cpu_coulomb_friction' and row.unit == 'CPU s'
    assert row.details['found'] == 'coulomb_friction'
    assert row.details['worst_parameter_error'] < 0.05
    # A diagnosis runs hundreds of simulations, each at least as costly as the nominal one.
    assert row.details['cost_in_simulations'] > row.details['simulations'] / 2
    assert row.ratio == pytest.approx(row.baseline_value / row.value)
    assert row.details['within'] == (row.value <= 2.0)
