"""What ``lumpbeam analyze BAG... --arm FILE --fit-links`` takes from each arm bag.

One :class:`~lumpbeam_ros.core.ident.arm.link_fit.ModeObservation` per bag, the seam between the
bags and the link fit: the joint angles where the last move came to rest and the modes of the free
vibration from then on. Both come from the identification that ``lumpbeam analyze BAG --arm
FILE`` and the live identifier run (:func:`~lumpbeam_ros.core.ident.bag_analysis.analyze_bag`
with the arm's joint count), so a bag's modes are the same whichever command reads them.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from lumpbeam_ros.base.errors import BagError, LumpbeamError
from lumpbeam_ros.base.interface import JOINT_STATES, TIP_POSE
from lumpbeam_ros.core.bagio.series import read_joint_states
from lumpbeam_ros.core.ident.arm.link_fit import MeasuredMode, ModeObservation
from lumpbeam_ros.core.ident.bag_analysis import analyze_bag
from lumpbeam_ros.core.ident.settings import IdentifierConfig
from lumpbeam_ros.core.model.arm.config import ArmConfig
from lumpbeam_ros.core.model.parameters import BeamParameters


def bag_observation(bag: str | Path, arm: ArmConfig, config: IdentifierConfig) -> ModeObservation:
    """A bag's final joint angles and the modes of its ring-down after the last move.

    Args:
        bag: An arm's bag: ``/joint_states`` and ``/tip_pose``.
        arm: The arm it was recorded on (its joint count).
        config: Identifier settings (``fit.max_modes``, ``ring_down.rest_tolerance_rad``).

    Returns:
        The observation.

    Raises:
        BagError: Not an arm's bag, or no mode out of the noise after the last move.
        LumpbeamError: As :func:`~lumpbeam_ros.core.ident.bag_analysis.analyze_bag` (no move, no
            rest after it, too few samples), named with the bag.
    """
    # An arm's ring-down leaves no load: the beam's B.12 figures stay undetermined, so the
    # beam passed through is only a placeholder.
    analysis = analyze_bag(bag, BeamParameters(), config, False, arm_joints=arm.n_joints)
    if analysis.rest is None or not analysis.modes:
        raise BagError(
            f'{bag}: no ring-down after the last move: no mode stands out of the noise in '
            f'{TIP_POSE}'
        )
    modes = tuple(MeasuredMode.of(m) for m in analysis.modes)
    return ModeObservation(np.asarray(analysis.rest.angles_rad), modes, str(bag))


def bag_observations(
    bags: Sequence[str | Path], arm: ArmConfig, config: IdentifierConfig
) -> list[ModeObservation]:
    """Every bag's :func:`bag_observation`, once all are checked to come from this arm.

    Raises:
        BagError: As :func:`bag_observation`, or a bag without ``/joint_states``.
        LumpbeamError: A bag whose ``/joint_states`` has another joint count than the arm,
            or names other joints than the first bag's.
    """
    names = []
    for bag in bags:
        try:
            series = read_joint_states(bag)
        except BagError as exc:
            raise BagError(f"{exc}: not a moving arm's record") from None
        names.append(series.names)
        if len(series.names) != arm.n_joints:
            raise LumpbeamError(
                f'{bag}: {JOINT_STATES} has {len(series.names)} joint(s), the arm '
                f'{arm.source or "given"} has {arm.n_joints}: a bag from another arm'
            )
        if series.names != names[0]:
            raise LumpbeamError(
                f'{bag}: {JOINT_STATES} names {list(series.names)}, {bags[0]} names '
                f'{list(names[0])}: bags from different arms'
            )
    return [bag_observation(bag, arm, config) for bag in bags]
