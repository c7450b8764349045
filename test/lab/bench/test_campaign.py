import pytest

from lumpbeam_lab.bench import campaign
from lumpbeam_lab.bench.runner import available_suites


# Two Dask clusters and a plain loop over the same bags: make test-slow runs it.
@pytest.mark.slow
def test_quick_run_compares_workers_with_a_plain_loop():
    one, two = campaign.run(quick=True)
    assert (one.name, two.name) == ('campaign_dask_1_worker', 'campaign_dask_2_workers')
    for result in (one, two):
        assert result.unit == 'bags/s' and result.value > 0 and result.baseline_value > 0
        assert result.ratio == pytest.approx(result.value / result.baseline_value)
        # The timing only means something if the cluster computed the loop's rows.
        assert result.details['same_rows_as_loop'] and result.details['failed'] == 0
        assert result.details['bags'] == 2
    assert one.baseline_value == two.baseline_value  # one baseline, measured once
    assert 'campaign' in available_suites()
