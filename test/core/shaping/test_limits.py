"""The modes a shaper can serve and the commands it shapes, bounded."""

import math

import numpy as np
import pytest

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.shaping.impulses import Mode
from lumpbeam_ros.core.shaping.limits import MAX_FREQUENCY_HZ, ShapingLimits
from lumpbeam_ros.core.shaping.shapers import design_shaper

LIMITS = ShapingLimits(max_added_s=10.0, max_command_s=600.0)


@pytest.mark.parametrize(
    ('kind', 'modes'),
    [
        ('zv', [Mode(3.0, 0.02)]),
        ('zvd', [Mode(0.1, 0.0)]),  # a whole period: exactly 10 s
        ('zv', [Mode(MAX_FREQUENCY_HZ, 0.0)]),  # half a period: one 1 ms sample
        ('ei', [Mode(2.0, 0.05), Mode(400.0, 0.3)]),
    ],
)
def test_shapers_within_the_limits_are_served(kind, modes):
    LIMITS.check_shaper(modes, design_shaper(kind, modes))


@pytest.mark.parametrize(
    ('frequency_hz', 'problem'),
    [
        (5.6e-4, r'would add 892.\d+ s to every move, more than max_added_s 10 s'),
        (0.099, r'would add 10.101 s'),
        (501.0, r'501 Hz is too fast to shape: .* 1 ms samples'),
        (1e300, r'1e\+300 Hz is too fast'),
    ],
)
def test_shapers_for_modes_too_slow_or_too_fast_are_refused_in_one_line(frequency_hz, problem):
    # 1e300 Hz once went out as "0.0000 s added", every move unshaped without a word.
    modes = [Mode(frequency_hz, 0.0)]
    with pytest.raises(LumpbeamError, match=problem) as caught:
        LIMITS.check_shaper(modes, design_shaper('zvd' if frequency_hz == 0.099 else 'zv', modes))
    assert '\n' not in str(caught.value)


def test_the_damped_frequency_is_what_must_be_sampled():
    # 600 Hz at zeta 0.6: damped 480 Hz, half a period above one sample.
    modes = [Mode(600.0, 0.6)]
    LIMITS.check_shaper(modes, design_shaper('zv', modes))
    assert 600.0 * math.sqrt(1 - 0.36) < MAX_FREQUENCY_HZ < 600.0


@pytest.mark.parametrize(('duration_s', 'refused'), [(600.0, False), (9000.0, True)])
def test_a_command_too_long_is_refused(duration_s, refused):
    command = JointTrajectory(np.array([0.0, duration_s]), np.array([[0.0], [1.0]]))
    if not refused:
        LIMITS.check_command(command)
        return
    with pytest.raises(LumpbeamError, match='lasts 9000 s, more than max_command_s 600 s'):
        LIMITS.check_command(command)
