import math

import pytest

from lumpbeam_lab.bench.live_graph import run
from lumpbeam_lab.bench.runner import available_suites, format_table


# A live graph at its rate (best-effort frames): make test-slow runs it on a machine no other
# worker keeps busy.
@pytest.mark.slow
@pytest.mark.ros
def test_quick_run_reports_the_demo_latency_against_the_camera_hop():
    assert 'live_graph' in available_suites()
    (row,) = run(quick=True)
    assert row.name == 'demo_e2e_latency_320x240' and row.unit == 'ms (p50)'
    details = row.details
    assert details['frames_published'] == 3 * 180
    assert details['poses_received'] > 0 and details['beam_params_received'] > 0
    # Updates that repeat a window (as after the stream's end) are counted, not timed.
    assert 0 < details['beam_params_timed'] <= details['beam_params_received']
    # Both latencies measured, p50 <= p99.
    assert 0 < details['tip_pose_latency_p50_ms'] <= details['tip_pose_latency_p99_ms']
    assert 0 < row.value <= details['beam_params_latency_p99_ms']
    assert row.baseline_value == details['tip_pose_latency_p50_ms']
    assert math.isclose(row.ratio, row.baseline_value / row.value)
    assert 'demo_e2e_latency_320x240' in format_table([row])
