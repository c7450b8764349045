"""What ``lumpbeam analyze BAG... --arm FILE --fit-links`` takes from each arm bag.

Two things per bag: where the joints came to rest (the last ``/joint_states``) and the modes
of the free vibration after the last move (``/tip_pose`` from the moment the joints stop).
They become one :class:`~lumpbeam_ros.arm.link_fit.ModeObservation`, the seam between the
bags and the link fit: :func:`bag_observation` is the only place that identifies modes, by
:func:`ringdown_modes`, so a better multi-mode identifier replaces that one function.

:func:`ringdown_modes` fits offset plus damped sinusoids
(:class:`~lumpbeam_ros.ident.sinusoid.DampedSinusoidFit`, started from the matrix pencil's
poles) to the tip's displacement along the direction it rings most, and keeps each mode whose
amplitude, frequency and damping stand out of their standard deviations.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lumpbeam_ros.arm.config import ArmConfig
from lumpbeam_ros.arm.link_fit import MeasuredMode, ModeObservation
from lumpbeam_ros.arm.moves import find_moves
from lumpbeam_ros.bagio import convert, open_bag, read_tip_poses
from lumpbeam_ros.errors import BagError, LumpbeamError
from lumpbeam_ros.ident.mode_estimate import ModeEstimate
from lumpbeam_ros.ident.pencil import MatrixPencil
from lumpbeam_ros.ident.sinusoid import DampedSinusoidFit
from lumpbeam_ros.interface import JOINT_STATE_TYPE, JOINT_STATES, TIP_POSE

#: Shortest ring-down worth fitting, s.
MIN_RINGDOWN_S = 1.0
#: A mode is kept when its amplitude, frequency and damping ratio are each at least this
#: many standard deviations from zero.
MIN_SIGNIFICANCE = 5.0
#: A mode within this fraction of an integer multiple of a stronger mode's frequency is
#: taken for its overtone.
HARMONIC_TOLERANCE = 2e-3
#: A mode within this fraction of a stronger mode's frequency is taken for the stronger
#: mode's drift with amplitude (an arm's modes lie much further apart).
SHADOW_TOLERANCE = 0.02
#: Damping ratios above this are not a ringing mode (a slow drift the fit soaked up).
MAX_DAMPING_RATIO = 0.5


#: What identifies the modes of a ring-down: ``(t, x, z, max_modes)`` of the tip (s, m, m)
#: from the moment the joints stop, to the modes that stand out of the noise.
RingdownIdentifier = Callable[[np.ndarray, np.ndarray, np.ndarray, int], Sequence[MeasuredMode]]


@dataclass(frozen=True)
class FinalJoints:
    """Where a bag's last move ended.

    Attributes:
        names: ``/joint_states`` names, in message order.
        angles_rad: The last message's angles, rad.
        rest_from_s: Stamp of the first message at those angles after the last move, s.
        end_s: Stamp of the last message, s.
    """

    names: tuple[str, ...]
    angles_rad: np.ndarray
    rest_from_s: float
    end_s: float


@dataclass(frozen=True)
class JointSeries:
    """A bag's ``/joint_states``, sorted by stamp.

    Attributes:
        names: The joint names, in message order.
        t: Stamps, s.
        q: Angles, rad, shape (len(t), len(names)).
    """

    names: tuple[str, ...]
    t: np.ndarray
    q: np.ndarray


def read_joint_states(bag: str | Path) -> JointSeries:
    """Reads ``/joint_states`` whole.

    Raises:
        BagError: No ``/joint_states`` (not an arm's bag), no message, messages whose joint
            names change, or angles that are not finite.
    """
    reader = open_bag(bag)
    if JOINT_STATES not in reader.topics:
        raise BagError(f"{bag}: no {JOINT_STATES} in the bag: not a moving arm's record")
    reader.require(JOINT_STATES, JOINT_STATE_TYPE)
    stamps: list[int] = []
    rows: list[np.ndarray] = []
    names: list[str] | None = None
    for _, msg in reader.messages(JOINT_STATES, JOINT_STATE_TYPE):
        ns, these, positions = convert.joint_state_values(msg)
        if names is None:
            names = these
        elif these != names:
            raise BagError(
                f'{bag}: {JOINT_STATES} names change from {names} to {these} within the bag'
            )
        if positions.size != len(these):
            raise BagError(
                f'{bag}: {JOINT_STATES} has {positions.size} positions for {len(these)} names'
            )
        stamps.append(ns)
        rows.append(positions)
    if names is None:
        raise BagError(f'{bag}: {JOINT_STATES} holds no messages')
    order = np.argsort(np.asarray(stamps), kind='stable')
    q = np.vstack(rows)[order]
    if not np.all(np.isfinite(q)):
        raise BagError(f'{bag}: {JOINT_STATES} holds angles that are not finite')
    t = np.asarray(stamps, dtype=float)[order] / convert.NS_PER_S
    # A repeated stamp (a message recorded twice) keeps its first message.
    t, first = np.unique(t, return_index=True)
    return JointSeries(tuple(names), t, q[first])


def read_final_joints(bag: str | Path) -> FinalJoints:
    """Reads ``/joint_states`` and finds when the joints came to rest for good.

    Raises:
        BagError: As :func:`read_joint_states`.
    """
    joints = read_joint_states(bag)
    t = joints.t
    moves = find_moves(t, joints.q)
    rest = moves[-1].end_s if moves else float(t[0])
    return FinalJoints(joints.names, joints.q[-1].copy(), rest, float(t[-1]))


def ringdown_modes(
    t: np.ndarray, x: np.ndarray, z: np.ndarray, max_modes: int = 3
) -> tuple[MeasuredMode, ...]:
    """The modes of a free vibration of the tip, each with standard deviations.

    The tip's ``(x, z)`` is projected on the direction it moves most (the principal axis of
    its displacements); the matrix pencil gives the poles to start from, and the damped
    sinusoid fit their values and covariance.

    Args:
        t: Stamps from when the joints stopped, s.
        x: Tip x, m.
        z: Tip z, m.
        max_modes: At most this many modes.

    Returns:
        The modes that stand out of the noise, by increasing frequency (maybe none).
    """
    y = _principal_displacement(x, z)
    rate = 1.0 / float(np.median(np.diff(t)))
    spare = 2
    pencil = MatrixPencil(order=1 + 2 * (max_modes + spare), pencil_length=60)
    try:
        poles = pencil.fit(t, y).modes
    except LumpbeamError:
        return ()
    guesses = [
        (m.damped_frequency_hz, m.damping_ratio)
        for m in poles
        if 0.0 < m.damping_ratio < MAX_DAMPING_RATIO
        and m.damped_frequency_hz < 0.4 * rate
        and not _harmonic(m, poles)
    ][:max_modes]
    while guesses:
        try:
            params = DampedSinusoidFit(n_modes=len(guesses)).fit(t, y, initial=guesses)
        except LumpbeamError:
            guesses = guesses[:-1]
            continue
        modes = [params.mode(k) for k in range(len(guesses))]
        kept = [m for m in modes if _stands_out(m) and not _harmonic(m, modes)]
        if len(kept) == len(modes):
            return tuple(
                MeasuredMode(
                    m.natural_frequency_hz,
                    m.natural_frequency_hz_std,
                    m.damping_ratio,
                    m.damping_ratio_std,
                )
                for m in sorted(kept, key=lambda m: m.natural_frequency_hz)
            )
        # Refit without the weakest: a mode that is only noise spoils the others' stds.
        weakest = min(range(len(modes)), key=lambda k: modes[k].amplitude)
        guesses = [g for k, g in enumerate(guesses) if k != weakest]
    return ()


def _stands_out(mode: ModeEstimate) -> bool:
    """A ringing mode whose amplitude, frequency and damping each stand out of their stds."""
    values = (
        mode.amplitude,
        mode.amplitude_std,
        mode.natural_frequency_hz,
        mode.natural_frequency_hz_std,
        mode.damping_ratio,
        mode.damping_ratio_std,
    )
    if not all(math.isfinite(v) for v in values):
        return False
    return (
        0.0 < mode.damping_ratio < MAX_DAMPING_RATIO
        and mode.amplitude > MIN_SIGNIFICANCE * mode.amplitude_std
        and mode.damping_ratio > MIN_SIGNIFICANCE * mode.damping_ratio_std
        and mode.natural_frequency_hz > MIN_SIGNIFICANCE * mode.natural_frequency_hz_std
    )


def _harmonic(mode: ModeEstimate, modes: Sequence[ModeEstimate]) -> bool:
    """Whether ``mode`` is an artefact of a stronger one, not a mode of its own.

    A large ring-down's geometric nonlinearity puts overtones at integer multiples of a
    mode's frequency, and its frequency drifting with the amplitude shows as a weaker mode
    beside it.
    """
    for other in modes:
        if not other.amplitude > mode.amplitude:
            continue
        ratio = mode.damped_frequency_hz / other.damped_frequency_hz
        order = round(ratio)
        if order >= 2 and abs(ratio - order) < HARMONIC_TOLERANCE * order:
            return True
        if abs(ratio - 1.0) < SHADOW_TOLERANCE:
            return True
    return False


def _principal_displacement(x: np.ndarray, z: np.ndarray) -> np.ndarray:
    """The displacement along the principal axis of ``(x, z)`` about their mean."""
    d = np.column_stack([x - np.mean(x), z - np.mean(z)])
    _, _, vt = np.linalg.svd(d, full_matrices=False)
    return np.asarray(d @ vt[0])


def bag_observation(
    bag: str | Path,
    joints: FinalJoints | None = None,
    max_modes: int = 3,
    identify: RingdownIdentifier = ringdown_modes,
) -> ModeObservation:
    """A bag's final joint angles and the modes of its ring-down after the last move.

    This is the seam between the bags and the link fit: the observation it returns is all
    :class:`~lumpbeam_ros.arm.link_fit.LinkParameterFit` needs, and ``identify`` is the one
    call that finds the modes.

    Args:
        bag: An arm's bag: ``/joint_states`` and ``/tip_pose``.
        joints: Its :func:`read_final_joints`, when already read.
        max_modes: At most this many modes.
        identify: ``(t, x, z, max_modes) -> modes`` of the tip's free vibration from the
            moment the joints stop (:func:`ringdown_modes` by default).

    Returns:
        The observation.

    Raises:
        BagError: Not an arm's bag, or no ring-down after the last move (too short a record
            after the joints stop, or no mode out of the noise).
    """
    joints = joints or read_final_joints(bag)
    poses = read_tip_poses(bag, TIP_POSE)
    after = poses.between(joints.rest_from_s, math.inf)
    span = after.end_s - after.start_s if len(after) else 0.0
    if len(after) < 20 or span < MIN_RINGDOWN_S:
        raise BagError(
            f'{bag}: no ring-down after the last move: {span:.2f} s of {TIP_POSE} after the '
            f'joints stop at {joints.rest_from_s:.3f} s (at least {MIN_RINGDOWN_S:g} s needed)'
        )
    modes = tuple(identify(after.t, after.x, after.z, max_modes))
    if not modes:
        raise BagError(
            f'{bag}: no ring-down after the last move: no mode stands out of the noise in '
            f'{span:.2f} s of {TIP_POSE}'
        )
    return ModeObservation(joints.angles_rad, modes, str(bag))


def bag_observations(
    bags: Sequence[str | Path],
    arm: ArmConfig,
    max_modes: int = 3,
    identify: RingdownIdentifier = ringdown_modes,
) -> list[ModeObservation]:
    """Every bag's :func:`bag_observation`, once all are checked to come from this arm.

    Raises:
        BagError: As :func:`read_final_joints` and :func:`bag_observation`.
        LumpbeamError: A bag whose ``/joint_states`` has another joint count than the arm,
            or names other joints than the first bag's.
    """
    finals = [read_final_joints(bag) for bag in bags]
    for bag, joints in zip(bags, finals, strict=True):
        if joints.angles_rad.size != arm.n_joints:
            raise LumpbeamError(
                f'{bag}: {JOINT_STATES} has {joints.angles_rad.size} joint(s), the arm '
                f'{arm.source or "given"} has {arm.n_joints}: a bag from another arm'
            )
        if joints.names != finals[0].names:
            raise LumpbeamError(
                f'{bag}: {JOINT_STATES} names {list(joints.names)}, {bags[0]} names '
                f'{list(finals[0].names)}: bags from different arms'
            )
    return [
        bag_observation(bag, joints, max_modes, identify)
        for bag, joints in zip(bags, finals, strict=True)
    ]
