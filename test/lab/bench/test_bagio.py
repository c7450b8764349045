import pytest

from lumpbeam_lab.bench import bagio


def test_quick_run_reports_every_figure():
    write, read, play = bagio.run(quick=True)
    assert write.name == 'bag_write_1mp_180fps' and write.unit == 'MB/s'
    assert write.details['messages_written'] == 72 and write.details['dropped'] == 0
    assert write.value > 0 and write.baseline_value > 0
    assert write.ratio == write.value / write.baseline_value
    assert read.name == 'bag_read_tip_poses' and read.details['poses'] == 30 * 180
    assert read.details['fast_equals_general'] and read.ratio == pytest.approx(
        read.value / read.baseline_value
    )
    assert play.name == 'play_timing_p99' and play.unit == 'ms'
    assert play.details['messages'] == 180  # 90 poses and 90 /clock ticks
    assert 0 <= play.details['p50_ms'] <= play.value <= play.details['max_ms']
