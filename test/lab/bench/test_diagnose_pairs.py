import math

import pytest

from lumpbeam_lab.bench import diagnose_pairs
from lumpbeam_lab.bench.bench_result import BenchResult
from lumpbeam_lab.bench.runner import available_suites, format_table


def _row(case, cpu, ratio, found, error):
    details = {'case': case, 'allowed_s': 30.0, 'found': found, 'worst_parameter_error': error}
    return BenchResult('diagnose_x', cpu, 'CPU s', 'exhaustive', cpu * ratio, ratio, details)


def test_the_case_table_has_one_row_per_case_in_its_own_columns():
    rows = [
        _row('base_compliance+quadratic_drag', 9.2, 6.0, 'base_compliance+quadratic_drag', 8e-4),
        _row('nominal x 20 seeds', 4.5, 10.5, 'none 20 of 20', math.nan),
    ]
    table = format_table(rows).splitlines()
    assert table[0].split() == [
        'case',
        'CPU',
        's',
        'allowed',
        'vs',
        'exhaustive',
        'found',
        'worst',
        'param',
        'error',
    ]
    assert table[1].split() == [
        'base_compliance+quadratic_drag',
        '9.2',
        '30',
        '6.0x',
        'base_compliance+quadratic_drag',
        '0.08',
        '%',
    ]
    assert table[2].split()[-1] == '-' and 'none 20 of 20' in table[2]
    assert 'diagnose_pairs' in available_suites()


@pytest.mark.slow
def test_quick_run_names_the_pair_and_times_both_searches():
    pair, nominal = diagnose_pairs.run(quick=True)
    assert pair.details['found'] == '+'.join(diagnose_pairs.CASES[0])
    assert pair.details['worst_parameter_error'] < 0.1
    assert pair.value > 0.0 and pair.baseline_value > 0.0
    assert nominal.details['found'] == 'none 2 of 2'
