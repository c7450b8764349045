import pytest

from lumpbeam_lab.bench import records
from lumpbeam_lab.bench.runner import available_suites


def test_the_suite_is_listed():
    assert 'records' in available_suites()


@pytest.mark.parametrize('name', ['half_a_hertz', 'quantized_ring'])
def test_a_synthetic_row_scores_the_product_and_every_peer(name):
    row = records.synthetic_row(name, records.RECORDS[name], seeds=2)
    assert row.name == f'records_{name}' and row.unit == 'zeta rel RMS'
    details = row.details
    assert details['lumpbeam_misses'] == 0 and details['lumpbeam_within_3_std'] == 1.0
    for method in ('lumpbeam', 'fft_logdec', 'era', 'ssi_cov'):
        assert f'{method}_misses' in details
    assert row.baseline.startswith('best peer (') and row.ratio == pytest.approx(
        row.baseline_value / row.value
    )


def test_the_running_shaker_gives_lines_and_no_mode():
    row = records.shaker_row()
    assert row.details['lumpbeam_status'] == 'ERROR' and row.details['lumpbeam_modes'] == []
    assert row.details['lumpbeam_lines_hz'] == pytest.approx([100.0, 120.0, 150.0], abs=0.05)


def test_a_speed_row_times_both_on_one_record():
    tap, target = records.SPEED['records_speed_0.25s_15khz']
    row = records.speed_row('records_speed_0.25s_15khz', tap, target)
    assert row.unit == 'CPU s' and row.value > 0 and row.baseline_value > 0
    assert row.details['modes_found'] == 2 and row.details['target_cpu_s'] == 0.5
