import pytest

from lumpbeam_lab.bench import cli
from lumpbeam_lab.bench.runner import available_suites
from lumpbeam_ros.apps.cli.main import main


def test_quick_run_times_the_help_against_the_bare_interpreter():
    results = cli.run(quick=True)
    assert [r.name for r in results] == ['cli_start_help', 'cli_start_analyze_help']
    for result in results:
        assert result.unit == 's' and result.baseline == 'python -c pass'
        assert result.value > 0 and result.baseline_value > 0
        assert result.ratio == result.baseline_value / result.value
        assert result.details['runs'] == 3
        assert result.details['cli_own_s'] == result.value - result.baseline_value
        assert result.value <= result.details['max_s']
    assert results[1].details['command'] == 'lumpbeam analyze --help'


def test_bench_only_cli_prints_both_rows(capsys):
    assert 'cli' in available_suites()
    assert main(['bench', '--only', 'cli', '--quick']) == 0
    table = capsys.readouterr().out
    assert 'cli_start_help ' in table and 'cli_start_analyze_help ' in table
    assert table.count('python -c pass') == 2


@pytest.mark.slow
def test_analyze_row_runs_a_whole_analysis_of_a_bag():
    result = cli.analyze_time(runs=1, duration_s=4.0)
    assert result.name == 'cli_start_analyze_4s_bag'
    assert result.details['command'] == 'lumpbeam analyze BAG (4 s, 180 Hz)'
    assert result.details['budget_s'] == cli.ANALYZE_BUDGET_S
    # A whole analysis imports numpy and scipy: it cannot start as fast as a bare interpreter.
    assert result.value > result.baseline_value and result.ratio < 1.0
