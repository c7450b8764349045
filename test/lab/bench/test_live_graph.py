import math

import pytest

from lumpbeam_lab.bench.live_graph import MAX_P99_MS, run
from lumpbeam_lab.bench.runner import available_suites, format_table


# A live graph at its rate (best-effort frames): make test-slow runs it on a machine no other
# worker keeps busy.
@pytest.mark.slow
@pytest.mark.ros
def test_quick_run_reports_the_params_latency_against_the_camera_hop_and_the_echo():
    assert 'live_graph' in available_suites()
    (row,) = run(quick=True)
    assert row.name == 'live_graph_320x240_idle' and row.unit == 'ms (/beam_params p99)'
    details = row.details
    assert details['busy_loops'] == 0
    assert details['frames_published'] == 3 * 180
    # Rounded to two decimals.
    assert details['poses_pct'] == pytest.approx(
        100 * details['poses_received'] / (3 * 180), abs=0.005
    )
    assert details['realtime_priority_camera'] in (0, 50) and details['realtime_permitted'] in (
        0,
        1,
    )
    assert details['beam_params_timed'] > 0 and details['echo_poses_pct'] > 0
    # Updates that repeat a window (as after the stream's end) are counted, not timed.
    assert details['beam_params_timed'] <= details['beam_params_received']
    # Every latency measured, p50 <= p99.
    for prefix in ('tip_pose_latency', 'echo_latency', 'beam_params_latency'):
        assert 0 < details[f'{prefix}_p50_ms'] <= details[f'{prefix}_p99_ms']
    assert row.value == details['beam_params_latency_p99_ms']
    assert row.baseline_value == details['tip_pose_latency_p99_ms']
    assert math.isclose(row.ratio, row.baseline_value / row.value)
    passed = row.value < MAX_P99_MS
    assert (f'{"pass" if passed else "FAIL"} /beam_params p99') in details['target']
    assert 'live_graph_320x240_idle' in format_table([row])
