import math

import pytest

from lumpbeam_ros.bench import ident
from lumpbeam_ros.bench.runner import available_suites
from lumpbeam_ros.model.parameters import BeamParameters


def test_quick_run_reports_both_figures_with_baselines():
    results = {r.name: r for r in ident.run(quick=True)}
    assert set(results) == {'ident_batch_throughput', 'ident_window_update_10s_180hz'}
    batch = results['ident_batch_throughput']
    assert batch.unit == 'samples/s' and batch.value > 0 and batch.baseline_value > 0
    assert batch.ratio == pytest.approx(batch.value / batch.baseline_value)
    assert batch.details['status'] == 'OK'
    # Both sides must identify the record, or the timing compares nothing.
    for side in ('ours', 'baseline'):
        assert batch.details[f'{side}_natural_frequency_hz_rel_error'] < 1e-3
        assert batch.details[f'{side}_stiffness_total_nm_per_rad_rel_error'] < 1e-2
    live = results['ident_window_update_10s_180hz']
    assert live.unit == 'ms/update' and 1799 <= live.details['samples'] <= 1801
    assert live.ratio == pytest.approx(live.baseline_value / live.value)
    assert math.isfinite(live.details['push_us_per_sample'])
    assert 'ident' in available_suites()


def test_baseline_identifies_the_synthetic_record():
    beam = BeamParameters()
    t, z, _ = ident.synthetic_record(12.0, beam)
    found = ident.baseline_identify(t, z, beam)
    assert found['natural_frequency_hz'] == pytest.approx(ident.F_HZ, rel=1e-3)
    assert found['damping_ratio'] == pytest.approx(ident.ZETA, rel=0.05)
