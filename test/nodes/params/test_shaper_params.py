import math

import pytest

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.shaping.impulses import Mode
from lumpbeam_ros.core.shaping.shapers import SHAPERS
from lumpbeam_ros.nodes.params.shaper_params import SHAPER_SCHEMA


def test_the_shapers_are_the_cores():
    assert SHAPER_SCHEMA['shaper'].choices == tuple(SHAPERS)
    assert set(SHAPER_SCHEMA['robust_shaper'].choices) == set(SHAPERS) - {'zv'}


@pytest.mark.parametrize(
    ('frequency_hz', 'damping_ratio'), [(0.0, 0.0), (1.0, 1.0), (1.0, -1e-9), (-1.0, 0.0)]
)
def test_the_mode_bounds_refuse_what_a_mode_refuses(frequency_hz, damping_ratio):
    problems = SHAPER_SCHEMA.first_problem(
        {'frequency_hz': frequency_hz, 'damping_ratio': damping_ratio}
    )
    assert problems is not None
    with pytest.raises(LumpbeamError):
        Mode(frequency_hz, damping_ratio)


def test_the_defaults_make_a_mode():
    d = SHAPER_SCHEMA.defaults()
    assert Mode(d['frequency_hz'], d['damping_ratio']).damped_period_s == 1.0
    assert math.isclose(d['robust_above'], 0.01)
