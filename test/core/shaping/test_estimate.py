"""Modes from an identifier status: valid ones taken, invalid ones never; the shaper chosen."""

import pytest

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.shaping.estimate import ModeEstimate, choose_shaper, estimate_from_status
from lumpbeam_ros.core.shaping.impulses import Mode

OK, WARN, ERROR, STALE = 0, 1, 2, 3


def _status(**extra):
    values = {
        'natural_frequency_hz': '3.2',
        'natural_frequency_hz_std': '0.001',
        'damping_ratio': '0.01',
        'damping_ratio_std': '0.0005',
        'mode_count': '2',
        'mode_2_natural_frequency_hz': '19.5',
        'mode_2_natural_frequency_hz_std': '0.05',
        'mode_2_damping_ratio': '0.02',
        'mode_2_damping_ratio_std': '0.002',
    }
    values.update(extra)
    return {k: v for k, v in values.items() if v is not None}


def test_every_valid_mode_up_to_the_limit():
    estimate = estimate_from_status(OK, _status(), max_modes=3)
    assert [m.mode for m in estimate.modes] == [Mode(3.2, 0.01), Mode(19.5, 0.02)]
    assert estimate.modes[1].frequency_std_hz == 0.05 and estimate.left_out == ()
    assert len(estimate_from_status(WARN, _status(), max_modes=1).modes) == 1


def test_one_mode_without_mode_count():
    estimate = estimate_from_status(OK, _status(mode_count=None), max_modes=3)
    assert [m.mode for m in estimate.modes] == [Mode(3.2, 0.01)]


@pytest.mark.parametrize(
    ('level', 'extra', 'problem'),
    [
        (ERROR, {}, 'status ERROR, no estimate'),
        (STALE, {}, 'status 3, no estimate'),
        (OK, {'natural_frequency_hz': 'nan'}, 'natural_frequency_hz is nan'),
        (OK, {'damping_ratio_std': 'inf'}, 'damping_ratio_std is inf'),
        (OK, {'natural_frequency_hz': None}, 'natural_frequency_hz missing'),
        (OK, {'damping_ratio_std': None}, 'damping_ratio_std missing'),
        (OK, {'damping_ratio': 'x'}, "damping_ratio is not a number: 'x'"),
        (
            OK,
            {'natural_frequency_hz_std': '4.0'},
            'natural_frequency_hz 3.2 has a standard deviation of 4.0',
        ),
        (OK, {'damping_ratio_std': '0.02'}, 'damping_ratio 0.01 has a standard deviation of 0.02'),
        (OK, {'natural_frequency_hz': '-3.2'}, 'natural frequency must be a positive number'),
        (OK, {'damping_ratio': '1.5', 'damping_ratio_std': '0.1'}, 'damping ratio must be in'),
    ],
)
def test_an_invalid_first_mode_is_no_estimate(level, extra, problem):
    with pytest.raises(LumpbeamError) as caught:
        estimate_from_status(level, _status(**extra), max_modes=3)
    assert str(caught.value).startswith(problem)


def test_an_invalid_higher_mode_is_left_out_with_the_reason():
    estimate = estimate_from_status(OK, _status(mode_2_natural_frequency_hz='nan'), 3)
    assert [m.mode for m in estimate.modes] == [Mode(3.2, 0.01)]
    assert estimate.left_out == ('mode 2: mode_2_natural_frequency_hz is nan',)


@pytest.mark.parametrize(
    ('stds', 'expected'),
    [((0.005, 0.05), 'zv'), ((0.06, 0.05), 'ei'), ((0.05, 0.2), 'zv'), ((0.005, 0.5), 'ei')],
)
def test_robust_shaper_when_a_frequency_is_uncertain(stds, expected):
    modes = [
        ModeEstimate(Mode(5.0, 0.01), stds[0], 0.0),
        ModeEstimate(Mode(20.0, 0.0), stds[1], 0),
    ]
    assert choose_shaper(modes, 'zv', 'ei', robust_above=0.01) == expected


@pytest.mark.parametrize('count', ['inf', 'nan', '-1', '0', '2.5', 'two', '1e300'])
def test_a_mode_count_that_is_no_count_leaves_the_first_mode_with_the_reason(count):
    # 'inf' once stopped the shaper node (int(inf): OverflowError).
    estimate = estimate_from_status(OK, _status(mode_count=count), max_modes=3)
    if count == '1e300':  # a count, if an absurd one: as many modes as the status holds
        assert len(estimate.modes) == 2
        return
    assert [m.mode for m in estimate.modes] == [Mode(3.2, 0.01)]
    assert estimate.left_out == (f'mode_count {count!r} is not a count',)
