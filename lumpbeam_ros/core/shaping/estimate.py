"""The modes to shape for, from an identifier's estimate, and the shaper it calls for.

The identifier's status (``/beam_params``, doc/interfaces.md) gives the first mode as
``natural_frequency_hz`` and ``damping_ratio`` and mode k >= 2 as
``mode_k_natural_frequency_hz`` and ``mode_k_damping_ratio`` (``mode_count`` of them), each
with its ``_std``, as Python ``repr`` strings. An estimate is invalid when the status is
ERROR, or a value or its standard deviation is missing, not a finite number, or the standard
deviation exceeds the value: a shaper is never built on it. A higher mode that is invalid is
left out; an invalid first mode invalidates the whole estimate.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.identification import MODE_COUNT_KEY, Status, mode_key
from lumpbeam_ros.core.shaping.impulses import Mode

FREQUENCY = 'natural_frequency_hz'
DAMPING = 'damping_ratio'


@dataclass(frozen=True)
class ModeEstimate:
    """An identified mode with the standard deviations of its figures.

    Attributes:
        mode: The mode.
        frequency_std_hz: Standard deviation of its natural frequency, Hz.
        damping_std: Standard deviation of its damping ratio.
    """

    mode: Mode
    frequency_std_hz: float
    damping_std: float

    @property
    def relative_frequency_std(self) -> float:
        """The frequency's standard deviation over its value."""
        return self.frequency_std_hz / self.mode.frequency_hz


@dataclass(frozen=True)
class Estimate:
    """The valid modes of one identifier status.

    Attributes:
        modes: At least one mode, the first mode first.
        left_out: Why each higher mode that is not in ``modes`` was left out.
    """

    modes: tuple[ModeEstimate, ...]
    left_out: tuple[str, ...] = ()


def _figure(values: Mapping[str, str], key: str) -> tuple[float, float]:
    """A value and its standard deviation; LumpbeamError when either is unusable."""
    pair = []
    for name in (key, f'{key}_std'):
        text = values.get(name)
        if text is None:
            raise LumpbeamError(f'{name} missing')
        try:
            number = float(text)
        except ValueError:
            raise LumpbeamError(f'{name} is not a number: {text!r}') from None
        if not math.isfinite(number):
            raise LumpbeamError(f'{name} is {text}')
        pair.append(number)
    value, std = pair
    if std < 0.0 or std > abs(value):
        raise LumpbeamError(f'{key} {value!r} has a standard deviation of {std!r}')
    return value, std


def _mode(values: Mapping[str, str], k: int) -> ModeEstimate:
    """Mode ``k`` (1: the top-level keys) of a status."""
    frequency, frequency_std = _figure(values, FREQUENCY if k == 1 else mode_key(k, FREQUENCY))
    damping, damping_std = _figure(values, DAMPING if k == 1 else mode_key(k, DAMPING))
    return ModeEstimate(Mode(frequency, damping), frequency_std, damping_std)


def _mode_count(text: str) -> int | None:
    """A status's mode count, or ``None`` when it is not a whole number of at least 1."""
    try:
        count = float(text)
    except ValueError:
        return None
    if not (math.isfinite(count) and count >= 1.0 and count.is_integer()):
        return None
    return int(count)


def estimate_from_status(level: int, values: Mapping[str, str], max_modes: int) -> Estimate:
    """The modes of an identifier status, at most ``max_modes``.

    Args:
        level: The status level (``OK``, ``WARN``, ``ERROR`` as diagnostic_msgs numbers them).
        values: The status's key-value pairs.
        max_modes: How many modes to take at most (>= 1).

    Returns:
        The valid modes.

    Raises:
        LumpbeamError: The status is not OK or WARN, or its first mode is invalid; the
            message says why.
    """
    if level not in (Status.OK, Status.WARN):
        name = Status(level).name if level in Status._value2member_map_ else str(level)
        raise LumpbeamError(f'status {name}, no estimate')
    modes = [_mode(values, 1)]
    left_out = []
    count = _mode_count(values.get(MODE_COUNT_KEY, '1'))
    if count is None:
        left_out.append(f'{MODE_COUNT_KEY} {values[MODE_COUNT_KEY]!r} is not a count')
        count = 1
    for k in range(2, min(count, max_modes) + 1):
        try:
            modes.append(_mode(values, k))
        except LumpbeamError as exc:
            left_out.append(f'mode {k}: {exc}')
    return Estimate(tuple(modes), tuple(left_out))


def choose_shaper(
    modes: Sequence[ModeEstimate], shaper: str, robust_shaper: str, robust_above: float
) -> str:
    """The shaper for identified modes: the robust one when a frequency is uncertain.

    Args:
        modes: The identified modes.
        shaper: The shaper when every frequency is well known (e.g. ``'zv'``).
        robust_shaper: The shaper otherwise (``'zvd'`` or ``'ei'``).
        robust_above: The relative standard deviation of a frequency above which it is
            uncertain (a ZV shaper leaves at most 5 % within about 3 % of its frequency,
            so 0.01 keeps a 3-sigma error inside that band).

    Returns:
        ``shaper`` or ``robust_shaper``.
    """
    uncertain = any(m.relative_frequency_std > robust_above for m in modes)
    return robust_shaper if uncertain else shaper
