"""The offline shaping loop: identified modes, the shaper node's choice, 90 % less."""

import numpy as np
import pytest
import yaml
from arm_cases import small_arm_document

from lumpbeam_lab.shaping_loop import LoopCase, minimum_jerk, run_loop, shaper_for
from lumpbeam_ros.core.ident.arm.link_fit import MeasuredMode


def test_the_shaper_node_would_take_zv_for_a_sure_mode_and_ei_for_an_unsure_one():
    sure, unsure = MeasuredMode(4.0, 0.001, 0.02, 0.001), MeasuredMode(4.0, 0.2, 0.02, 0.001)
    assert shaper_for([sure])[0] == 'zv'
    kind, impulses = shaper_for([unsure])
    assert kind == 'ei' and impulses.amplitude.sum() == pytest.approx(1.0)


def test_a_minimum_jerk_move_rests_at_both_ends():
    move = minimum_jerk(np.zeros(2), np.array([0.5, -0.2]), 0.4)
    assert move.angles_rad[0] == pytest.approx([0, 0])
    assert move.angles_rad[-1] == pytest.approx([0.5, -0.2])
    # Rest to rest: the first and last steps are tiny (zero velocity at both ends).
    assert np.abs(move.angles_rad[1] - move.angles_rad[0]).max() < 1e-6
    assert np.abs(move.angles_rad[-1] - move.angles_rad[-2]).max() < 1e-6


def test_the_loop_rings_90_percent_less_after_identifying(tmp_path):
    config = tmp_path / 'small.yaml'
    config.write_text(yaml.safe_dump(small_arm_document(1, plane='horizontal')))
    report, outcome = run_loop(LoopCase('small', config, (0.0,), (0.5,), 0.3), tmp_path)
    assert outcome.reduction > 0.9
    assert report.startswith('small: identified') and '% less' in report
