import math

import numpy as np
import pytest

from lumpbeam_lab.bench import crb
from lumpbeam_lab.bench.runner import available_suites


def test_the_bound_of_a_long_undamped_sinusoid_is_the_textbook_one():
    # Frequency of a sinusoid of amplitude A in white noise sigma, N samples over T seconds,
    # phase and offset unknown: sd(f) = sqrt(6) sigma / (pi A T sqrt(N)) for large N.
    t = np.arange(0.0, 20.0, 1.0 / 200.0)
    theta = np.array([0.0, 1e-3, 1e-9, 3.0, 0.3])
    bound = crb.cramer_rao(t, theta, 2e-5)
    expected = math.sqrt(6.0) * 2e-5 / (math.pi * 1e-3 * 20.0 * math.sqrt(t.size))
    assert bound[3] == pytest.approx(expected, rel=0.02)
    # Linear in the noise.
    assert crb.cramer_rao(t, theta, 2e-4)[3] == pytest.approx(10.0 * bound[3], rel=1e-9)


def test_quick_rows_compare_the_identifier_with_the_bound():
    assert 'crb' in available_suites()
    row = crb.level_row(200e-6, 2)
    assert row.name == 'crb_200um' and row.details['trials'] == 2
    assert row.ratio == pytest.approx(row.baseline_value / row.value)
    d = row.details
    assert d['f_rms_over_bound'] == pytest.approx(row.value / row.baseline_value)
    # No estimator beats the bound by much over two trials; the identifier's damping is
    # close to it and its reported sd holds.
    assert d['zeta_rms_over_bound'] > 0.1 and d['zeta_rms_in_reported_std'] < 3.0
    assert d['f_rms_in_reported_std'] < 3.0
