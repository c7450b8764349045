from lumpbeam_lab.bench.model import run


def test_quick_suite_measures_against_radau():
    results = run(quick=True)
    drop = results[0]
    assert drop.baseline.startswith("solve_ivp(method='Radau'")
    assert drop.value > 0 and drop.baseline_value > 0
    assert drop.ratio == drop.baseline_value / drop.value
    assert drop.details['max_tip_difference_um'] < 10.0
    assert results[1].name == 'simulate_drop_test_ns30_cost'
