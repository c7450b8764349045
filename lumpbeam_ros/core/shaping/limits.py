"""What a shaper can serve: the modes it shapes for and the commands it shapes, bounded.

A mode identified from a topic is a number a buggy driver or a mis-scaled estimate can make
anything. Two kinds a shaper cannot serve:

- too fast: a ZV shaper's second impulse comes half a damped period after the first; once
  that is under the shaped command's sample interval (1 ms,
  :data:`~lumpbeam_ros.core.shaping.apply.MAX_STEP_S`) the shaped command is the command,
  and shaping would claim a cancellation it does not do;
- too slow: the shaper delays the end of every move by its duration (half a period for ZV,
  a whole one for ZVD); past ``max_added_s`` it turns a 1 s move into minutes.

A command is bounded too: its length (``max_command_s``), since the shaped one is sampled at
1 kHz over all of it. :class:`ShapingLimits` holds both bounds and refuses, in one line that
names the value, what lies outside them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.shaping.apply import MAX_STEP_S
from lumpbeam_ros.core.shaping.impulses import Impulses, Mode

#: The fastest mode a shaped command sampled at 1 kHz can cancel: half its damped period is
#: one sample interval, Hz.
MAX_FREQUENCY_HZ = 1.0 / (2.0 * MAX_STEP_S)


@dataclass(frozen=True)
class ShapingLimits:
    """The bounds of a shaper's modes and commands.

    Attributes:
        max_added_s: The longest a shaper may make a move, s.
        max_command_s: The longest command shaped, s.
    """

    max_added_s: float
    max_command_s: float

    def check_shaper(self, modes: Sequence[Mode], impulses: Impulses) -> None:
        """Refuses a shaper for a mode too fast to sample or too slow to wait for.

        Raises:
            LumpbeamError: A mode above :data:`MAX_FREQUENCY_HZ`, or impulses lasting more
                than ``max_added_s``.
        """
        for mode in modes:
            damped = mode.frequency_hz * math.sqrt(max(0.0, 1.0 - mode.damping_ratio**2))
            if not damped <= MAX_FREQUENCY_HZ:
                raise LumpbeamError(
                    f'a mode of {mode.frequency_hz:.6g} Hz is too fast to shape: half its '
                    f"period is under the shaped command's {1e3 * MAX_STEP_S:g} ms samples "
                    f'(at most {MAX_FREQUENCY_HZ:g} Hz)'
                )
        if not impulses.duration_s <= self.max_added_s:
            slowest = min(mode.frequency_hz for mode in modes)
            raise LumpbeamError(
                f'the shaper for {slowest:.6g} Hz would add {impulses.duration_s:.6g} s to '
                f'every move, more than max_added_s {self.max_added_s:g} s'
            )

    def check_command(self, trajectory: JointTrajectory) -> None:
        """Refuses a command longer than ``max_command_s``.

        Raises:
            LumpbeamError: The command lasts longer.
        """
        if not trajectory.duration_s <= self.max_command_s:
            raise LumpbeamError(
                f'it lasts {trajectory.duration_s:.6g} s, more than max_command_s '
                f'{self.max_command_s:g} s'
            )
