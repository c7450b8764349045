"""Moves found in joint angles: rests split them, short pauses do not, bad input refused."""

import numpy as np
import pytest

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.arm.moves import find_moves

T = np.arange(0.0, 6.0, 0.01)


def ramp(t, start, end, height):
    return height * np.clip((t - start) / (end - start), 0.0, 1.0)


def test_two_moves_separated_by_a_rest():
    q = np.column_stack([ramp(T, 0.5, 1.0, 0.4) - ramp(T, 3.0, 3.4, 0.4), ramp(T, 0.5, 1.2, -1)])
    first, second = find_moves(T, q)
    assert (first.start_s, first.end_s) == pytest.approx((0.5, 1.2))
    assert first.final_rad == pytest.approx([0.4, -1.0])
    assert (second.start_s, second.end_s) == pytest.approx((3.0, 3.4))
    assert second.final_rad == pytest.approx([0.0, -1.0])


def test_a_short_pause_inside_a_move_does_not_end_it():
    q = ramp(T, 1.0, 1.2, 0.2) + ramp(T, 1.5, 1.7, 0.2)
    (move,) = find_moves(T, q)
    assert (move.start_s, move.end_s) == pytest.approx((1.0, 1.7))
    assert len(find_moves(T, q, min_rest_s=0.2)) == 2


def test_joints_at_rest_have_no_move_and_bad_input_is_refused():
    assert find_moves(T, np.zeros(T.size)) == ()
    with pytest.raises(LumpbeamError, match='600 stamps for 5'):
        find_moves(T, np.zeros(5))
    with pytest.raises(LumpbeamError, match='must increase'):
        find_moves(T[::-1], np.zeros(T.size))
