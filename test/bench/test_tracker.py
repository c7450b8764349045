from lumpbeam_ros.bench.runner import available_suites
from lumpbeam_ros.bench.tracker import run


def test_quick_run_reports_speed_and_accuracy_against_same_run_baselines():
    assert 'tracker' in available_suites()
    speed, accuracy = run(quick=True)
    assert speed.name == 'tracker_fps_640x480'
    assert speed.value > 0 and speed.baseline_value > 0
    assert abs(speed.ratio - speed.value / speed.baseline_value) < 1e-9
    assert speed.details['frames_lost'] == 0
    assert speed.details['baseline_frames_found'] == speed.details['frames']
    assert 0 < speed.details['z_rms_um'] < 20
    assert accuracy.unit == 'um'
    # Free PnP per frame scatters far more than the plane-constrained fit.
    assert accuracy.baseline_value > 5 * accuracy.value
