"""The workspace's moves shaped by a learned arm and judged by MuJoCo (the lab's table)."""

from dataclasses import replace

import numpy as np
import pytest
from arm_cases import small_arm

from lumpbeam_lab import workspace_shaping
from lumpbeam_lab.workspace_shaping import (
    MoveRow,
    WorkspaceCase,
    cases,
    learned_arm,
    shaped_rows,
    table,
    tapered_two_link,
)


def test_the_two_link_arm_tapers():
    arm = tapered_two_link()
    for link in arm.links:
        assert np.all(np.diff(link.ei_nm2) < 0) and np.all(np.diff(link.segment_masses_kg) < 0)


def test_the_table_gives_the_least_and_median_reductions():
    rows = [
        MoveRow('a', 1e-3, 5e-4, 1e-6, 1e-6, 0.3, 1.0),
        MoveRow('b', 2e-3, 1e-4, 4e-5, 4e-5, 0.3, 1.0),
        MoveRow('c', 1e-3, 2e-3, 1e-5, 1e-5, 0.3, 1.0),
    ]
    lines = table('arm', rows)
    assert len(lines) == 2 + 3 + 1
    assert lines[-1].endswith('ZVD -100.00 % / 50.00 %, tuned 98.00 % / 99.00 %')


@pytest.mark.slow
def test_the_learned_arm_shapes_a_fast_move_that_mujoco_leaves_still(tmp_path):
    case = cases()['two_link']
    nominal, learned = learned_arm(case, tmp_path, seed=1)
    for fit, truth, off in zip(learned.links, case.truth.links, nominal.links, strict=True):
        k = [float(link.spring_stiffness()[0]) for link in (fit, truth, off)]
        assert abs(k[2] / k[1] - 1) == pytest.approx(0.2)
        assert k[0] == pytest.approx(k[1], rel=0.01)
    # The elbow through 2.6 rad in 0.6 s, the hardest of the table.
    fast = replace(case, moves=case.moves[:1])
    (row,) = shaped_rows(fast, learned)
    assert row.untuned_reduction < 0.5
    assert row.tuned_reduction > 0.95
    assert row.tuned < row.untuned


@pytest.mark.slow
def test_the_command_learns_and_prints_a_small_arm(monkeypatch, capsys):
    small = WorkspaceCase(
        'small',
        small_arm(2),
        ((0.3, -0.4), (-0.4, 1.0), (0.8, 0.6)),
        (0.0, 0.03),
        (((0.0, 0.0), (0.5, -0.6), 0.5),),
    )
    monkeypatch.setattr(workspace_shaping, 'cases', lambda: {'small': small})
    assert workspace_shaping.main(['--arms', 'small']) == 0
    out = capsys.readouterr().out
    assert 'small: links learned from 3 ring-downs' in out
    assert '[0.0, 0.0] -> [0.5, -0.6] in 0.5 s' in out and 'reduction, least / median' in out
