import numpy as np
import pytest

from lumpbeam_ros.core.model import rules


def test_b12_roundtrip():
    force = 4.5 * 9.81
    k = rules.total_stiffness_from_deflection(force, 2.3107, 0.0403)
    assert k == pytest.approx(3899.1, rel=1e-3)  # the paper's k_tE
    assert rules.deflection_from_total_stiffness(force, 2.3107, k) == pytest.approx(0.0403)


@pytest.mark.parametrize('n', [1, 2, 10])
def test_joint_rules(n):
    k = rules.joint_stiffnesses(100.0, n)
    assert k[0] == 100.0
    assert np.all(k[1:] == 50.0)  # B.10: two springs in series
    assert np.array_equal(rules.joint_dampings(100.0, n), k)  # B.11


def test_identified_rules():
    assert rules.identified_segment_stiffness(3899.1, 10) == pytest.approx(38991.0)
    assert rules.identified_segment_damping(12.0, 0.08, 10) == pytest.approx(9.6)
    assert rules.total_damping_from_ratio(0.002, 2 * np.pi * 3.24) == pytest.approx(
        0.0814, rel=1e-3
    )


def test_lumped_angle_equals_analytic():
    # B.6/B.7: one spring of 2EI/L gives the exact end slope of B.4.
    force, length, ei = 10.0, 2.0, 500.0
    k = rules.analytic_segment_stiffness(ei, length)
    assert force * length / k == pytest.approx(rules.end_load_slope(force, length, ei))
