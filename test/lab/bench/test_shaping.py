from lumpbeam_lab.bench.runner import available_suites
from lumpbeam_lab.bench.shaping import run


def test_quick_suite_measures_against_fftconvolve():
    assert 'shaping' in available_suites()
    one, two, tuned, latency = run(quick=True)
    assert one.baseline == 'scipy.signal.fftconvolve' and one.unit == 'ms per joint'
    assert one.value > 0 and one.baseline_value > 0
    assert one.ratio == one.baseline_value / one.value
    assert (one.details['impulses'], two.details['impulses']) == (3, 9)
    # Both compute the same convolution, up to the baseline's impulses rounded to 1 ms.
    assert one.details['max_difference_rad'] < 0.01
    assert two.details['max_difference_rad'] < 0.01

    # The arm's move: tuned against untuned in CPU seconds, and what the tuning bought.
    assert tuned.unit == 'CPU s' and tuned.ratio == tuned.baseline_value / tuned.value
    assert tuned.details['tuned_residual_m'] < tuned.details['untuned_residual_m']
    assert tuned.details['tuned_reduction'] > 0.99
    assert tuned.details['target'].split()[0] in ('pass', 'FAIL')
    # The shaper node's work by the model: a p99 against the fixed shaper's.
    assert latency.unit == 'ms p99' and latency.value > 0 and latency.baseline_value > 0
    assert latency.details['points'] == 101
