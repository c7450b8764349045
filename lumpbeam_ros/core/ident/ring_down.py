"""An arm's free vibration: where its joints stop, and the tip's swing after that.

A drop test's free vibration starts at the load's release; an arm's starts where its joints
stop (``/joint_states``): from then on the links ring down about their static equilibrium at
the joints' final angles, a free decay like the drop test's, with no load released (so no
stiffness by B.12). The arm is at rest while every joint stays within
``ring_down.rest_tolerance_rad`` of its angle at the first sample of the stretch; the same
rule runs on a whole bag (:func:`rest_stretches`) and live (:class:`RestTracker`).

The tip of an arm swings across its last link, which may point anywhere in the x-z plane:
the fit takes the tip's displacement along the principal direction of its motion over the
ring-down (the largest eigenvector of the covariance of x and z), which for a beam lying
along x is its z.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.release import Release
from lumpbeam_ros.core.ident.samples import PoseWindow

#: ``release_source`` of a free vibration that starts where the joints stop.
SOURCE = 'joint_states'


@dataclass(frozen=True)
class JointRest:
    """A stretch in which every joint stays within the tolerance of its first angles.

    Attributes:
        start_s: Stamp of the stretch's first sample: where the joints stopped, s.
        end_s: Stamp of its last sample, s.
        angles_rad: The joints' angles at ``end_s`` (where they came to rest), rad.
        after_move: Whether the joints moved before it (a ring-down), or it opens the record.
        moved_again: Whether the joints moved after it.
    """

    start_s: float
    end_s: float
    angles_rad: tuple[float, ...]
    after_move: bool
    moved_again: bool = False

    @property
    def duration_s(self) -> float:
        """How long the joints stayed at rest, s."""
        return self.end_s - self.start_s


class RestTracker:
    """Follows ``/joint_states`` and keeps where the joints last stopped.

    Args:
        tolerance_rad: How far a joint may stray from its angle at the stop and still be at
            rest, rad.
    """

    def __init__(self, tolerance_rad: float):
        if not tolerance_rad > 0.0:
            raise ValueError('the rest tolerance must be positive')
        self.tolerance_rad = float(tolerance_rad)
        self.current: JointRest | None = None
        self.previous: JointRest | None = None
        self._anchor = np.zeros(0)

    def clear(self) -> None:
        """Forgets every stop (a clock jumping back)."""
        self.current = self.previous = None

    def push(self, stamp: float, angles: np.ndarray) -> bool:
        """Adds one sample of joint angles.

        Args:
            stamp: Its stamp, s (not before the last one).
            angles: The joints' angles, rad.

        Returns:
            Whether it was used (a non-finite or out-of-order sample, or one with another
            number of joints than the stretch's, is not).
        """
        angles = np.asarray(angles, dtype=float)
        if not (math.isfinite(stamp) and angles.size and np.all(np.isfinite(angles))):
            return False
        current = self.current
        if current is not None and (
            stamp < current.end_s or angles.size != len(current.angles_rad)
        ):
            return False
        if current is not None and np.max(np.abs(angles - self._anchor)) <= self.tolerance_rad:
            self.current = replace(current, end_s=stamp, angles_rad=tuple(angles.tolist()))
            return True
        if current is not None:
            self.previous = replace(current, moved_again=True)
        self._anchor = angles
        self.current = JointRest(
            stamp, stamp, tuple(angles.tolist()), after_move=current is not None
        )
        return True

    def ring_down(self, min_duration_s: float = 0.0) -> JointRest | None:
        """The latest stretch at rest after a move that lasted ``min_duration_s``, or None."""
        for rest in (self.current, self.previous):
            if rest is not None and rest.after_move and rest.duration_s >= min_duration_s:
                return rest
        return None


def rest_stretches(t: np.ndarray, angles: np.ndarray, tolerance_rad: float) -> list[JointRest]:
    """Every stretch at rest of a record of joint angles, oldest first.

    The rule of :class:`RestTracker` on a whole record: each stretch runs from its first
    sample to the last before one that strays more than ``tolerance_rad`` from it; the
    search for that sample goes by numpy blocks, so a long rest costs few Python steps.

    Args:
        t: Stamps, s, increasing.
        angles: Joint angles, rad, shape (len(t), n_joints), finite.
        tolerance_rad: As :class:`RestTracker`.

    Returns:
        The stretches (a moving sample opens a new one).
    """
    t = np.asarray(t, dtype=float)
    q = np.asarray(angles, dtype=float).reshape(t.size, -1)
    stretches: list[JointRest] = []
    n = t.size
    i = 0
    while i < n:
        stop = n
        j, block = i + 1, 16
        while j < n:
            off = np.flatnonzero(np.any(np.abs(q[j : j + block] - q[i]) > tolerance_rad, axis=1))
            if off.size:
                stop = j + int(off[0])
                break
            j += block
            block *= 2
        last = stop - 1
        stretches.append(
            JointRest(
                float(t[i]),
                float(t[last]),
                tuple(q[last].tolist()),
                after_move=i > 0,
                moved_again=stop < n,
            )
        )
        i = stop
    return stretches


def last_ring_down(stretches: list[JointRest], min_duration_s: float) -> JointRest:
    """The free vibration after the last move: its stretch at rest.

    Raises:
        LumpbeamError: The joints never move, or never rest long enough after a move.
    """
    after = [s for s in stretches if s.after_move]
    if not after:
        raise LumpbeamError('the joints never move: no ring-down after a move')
    long_enough = [s for s in after if s.duration_s >= min_duration_s]
    if not long_enough:
        raise LumpbeamError(
            f'the joints rest at most {max(s.duration_s for s in after):.3g} s after a move, '
            f'need {min_duration_s:.3g} s (at rest: within ring_down.rest_tolerance_rad)'
        )
    return long_enough[-1]


def min_rest_s(window: PoseWindow, min_samples: int) -> float:
    """How long the joints must rest: as many pose periods as an identification needs.

    Args:
        window: The poses (their median period).
        min_samples: ``quality.min_samples``.

    Returns:
        The least duration of a ring-down, s (0 with fewer than two poses).
    """
    step = float(np.median(np.diff(window.t))) if len(window) > 1 else 0.0
    return min_samples * step


def no_ring_down_message(tolerance_rad: float) -> str:
    """What the live identifier says while an arm's joints have not stopped after a move."""
    return (
        'no ring-down yet: the joints have not stopped after a move (at rest: '
        f'within ring_down.rest_tolerance_rad = {tolerance_rad:g} rad)'
    )


def swing_after(window: PoseWindow, rest: JointRest) -> tuple[PoseWindow, Release]:
    """The tip along its swing over a rest, and the release its free vibration starts at."""
    return along_swing(window, rest.start_s, rest.end_s), ring_down_release(rest)


def ring_down_release(rest: JointRest) -> Release:
    """The start of the free vibration where the joints stopped, as the identifier takes it.

    No load leaves, so the release carries no mass and no static level (the stiffness of
    B.12 is not determined); the decay ends where the joints move again.
    """
    return Release(
        time_s=rest.start_s,
        confidence=1.0,
        source=SOURCE,
        load_kg=0.0,
        decay_end_s=rest.end_s if rest.moved_again else math.inf,
    )


def along_swing(window: PoseWindow, start_s: float, end_s: float) -> PoseWindow:
    """The window with ``z`` replaced by the tip's position along its swing.

    The direction is the principal axis of the tip's (x, z) over ``start_s .. end_s``,
    signed to point up (+z) when it can; without a measured x the window is returned as is.

    Args:
        window: The poses.
        start_s: Start of the ring-down, s.
        end_s: Its end, s.

    Returns:
        A window of the same stamps whose ``z`` is ``u_x x + u_z z``.
    """
    keep = (window.t >= start_s) & (window.t <= end_s)
    x, z = window.poses.x, window.z
    if np.count_nonzero(keep) < 3 or not np.all(np.isfinite(x[keep])):
        return window
    points = np.column_stack([x[keep], z[keep]])
    points = points - points.mean(axis=0)
    _, vectors = np.linalg.eigh(points.T @ points)
    u = vectors[:, -1]
    if u[1] < 0.0 or (u[1] == 0.0 and u[0] < 0.0):
        u = -u
    along = u[0] * np.nan_to_num(x) + u[1] * z
    return replace(window, poses=replace(window.poses, z=along))
