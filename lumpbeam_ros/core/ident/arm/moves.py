"""The moves in a record of joint angles: when the joints leave rest and where they stop.

A move starts at the last sample before the joints leave their angles and ends at the first
sample at the angles they then keep, by the rule of rest that finds an arm's ring-down
(:func:`~lumpbeam_ros.core.ident.ring_down.rest_stretches`); a rest shorter than ``min_rest_s``
inside a move (the flat stretches of a short move convolved with a shaper's impulses) does
not end it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.ring_down import rest_stretches

#: Joints that stay within this of the angles they stopped at are at rest, rad.
REST_TOLERANCE_RAD = 1e-9
#: A rest at least this long ends a move, s.
MIN_REST_S = 0.5


@dataclass(frozen=True)
class Move:
    """One move of the joints.

    Attributes:
        start_s: The last sample at rest before it, s.
        end_s: The first sample at its final angles, s.
        final_rad: The angles it ends at, rad.
    """

    start_s: float
    end_s: float
    final_rad: np.ndarray


def find_moves(
    t: np.ndarray,
    q: np.ndarray,
    min_rest_s: float = MIN_REST_S,
    tolerance_rad: float = REST_TOLERANCE_RAD,
) -> tuple[Move, ...]:
    """Splits joint angles into moves.

    Args:
        t: Increasing stamps, s.
        q: Angles, rad, shape (len(t), n_joints) (or (len(t),) for one joint).
        min_rest_s: The shortest rest that separates two moves, s.
        tolerance_rad: Joints within this of the angles they stopped at are at rest, rad.

    Returns:
        The moves in time order (none when the joints never move).

    Raises:
        LumpbeamError: Stamps and angles of different lengths, or stamps not increasing.
    """
    t = np.asarray(t, dtype=float)
    q = np.asarray(q, dtype=float)
    q = q[:, None] if q.ndim == 1 else q
    if t.ndim != 1 or q.ndim != 2 or q.shape[0] != t.size:
        raise LumpbeamError(f'moves: {t.size} stamps for {q.shape[0]} joint samples')
    if np.any(np.diff(t) <= 0.0):
        raise LumpbeamError('moves: the stamps must increase')
    stretches = rest_stretches(t, q, tolerance_rad)
    # Moves run between the stretches at rest that separate them: the record's first and
    # last, and every rest that lasts min_rest_s (a shorter one is a pause inside a move).
    bounds = [
        rest
        for k, rest in enumerate(stretches)
        if k in (0, len(stretches) - 1) or rest.duration_s >= min_rest_s
    ]
    return tuple(
        Move(before.end_s, after.start_s, np.asarray(after.angles_rad))
        for before, after in zip(bounds, bounds[1:], strict=False)
    )
