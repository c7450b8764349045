import pytest

from lumpbeam_lab.bench import ident
from lumpbeam_lab.bench.runner import available_suites
from lumpbeam_ros.core.model.parameters import BeamParameters


def test_quick_run_reports_both_figures_with_baselines():
    results = {r.name: r for r in ident.run(quick=True)}
    assert set(results) == {
        'analyze_bag_throughput',
        'ident_batch_throughput',
        'ident_window_update_10s_180hz',
        'ident_modes_12s_window',
    }
    modes = results['ident_modes_12s_window']
    assert modes.unit == 'ms CPU' and modes.ratio == pytest.approx(
        modes.value / modes.baseline_value
    )
    # The 0.5 kg tip body's modes 1 and 2 (5.37 and 38.7 Hz); a third is refused.
    assert modes.details['mode_frequencies_hz'] == pytest.approx([5.374, 38.70], rel=2e-3)
    bag = results['analyze_bag_throughput']
    assert bag.unit == 'pose msgs/s' and bag.details['status'] == 'OK'
    assert bag.details['poses'] == 30 * 180 + 1
    assert bag.ratio == pytest.approx(bag.value / bag.baseline_value)
    batch = results['ident_batch_throughput']
    assert batch.unit == 'samples/s' and batch.value > 0 and batch.baseline_value > 0
    assert batch.ratio == pytest.approx(batch.value / batch.baseline_value)
    assert batch.details['status'] == 'OK'
    # Both sides must identify the record, or the timing compares nothing; ours must also
    # be honest about it (the baseline's white-noise std is not, at 4 cm of amplitude).
    for side in ('ours', 'baseline'):
        assert batch.details[f'{side}_natural_frequency_hz_rel_error'] < 1e-3
        assert batch.details[f'{side}_stiffness_total_nm_per_rad_rel_error'] < 1e-2
    for key in ident.KEYS:
        assert batch.details[f'ours_{key}_error_in_std'] < 3.0
    live = results['ident_window_update_10s_180hz']
    assert live.unit == 'ms/update' and 1799 <= live.details['window_samples'] <= 1801
    assert live.details['samples_per_update'] == 90 and live.details['updates'] == 12
    assert live.ratio == pytest.approx(live.baseline_value / live.value)
    assert live.details['ours_natural_frequency_hz_rel_error'] < 1e-4
    assert live.details['push_us_per_sample'] > 0
    assert 'ident' in available_suites()


def test_baseline_identifies_the_model_record():
    beam = BeamParameters()
    t, z, _ = ident.drop_record(12.0, beam)
    truth = ident.model_truth(beam)
    found = ident.baseline_identify(t, z, beam)
    assert found['natural_frequency_hz'] == pytest.approx(truth['natural_frequency_hz'], rel=1e-4)
    assert found['damping_ratio'] == pytest.approx(truth['damping_ratio'], rel=0.05)
    k = truth['stiffness_total_nm_per_rad']
    assert found['stiffness_total_nm_per_rad'] == pytest.approx(k, rel=1e-3)
    assert found['natural_frequency_hz_std'] > 0
