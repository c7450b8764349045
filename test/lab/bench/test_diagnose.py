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
