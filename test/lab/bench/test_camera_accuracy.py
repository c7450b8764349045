from lumpbeam_lab.bench.camera_accuracy import run
from lumpbeam_lab.bench.runner import available_suites


def test_quick_run_prints_one_row_against_the_target(capsys):
    assert 'camera-accuracy' in available_suites()
    (row,) = run(quick=True)
    printed = capsys.readouterr().out
    assert row.details['conditions'] in printed and 'z rms' in printed and 'PASS' in printed
    assert row.unit == 'um' and row.baseline_value == 10.0
    assert 0 < row.value <= 10.0 and row.ratio == 10.0 / row.value
    assert row.details['frames_lost'] == 0
