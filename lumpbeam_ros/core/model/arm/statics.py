"""The arm at rest at given joint angles, and its linear modes about that rest."""

from __future__ import annotations

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.modes import LinearModel, Modes, linear_modes
from lumpbeam_ros.core.model.statics import static_equilibrium


def arm_equilibrium(model: ArmModel, q: np.ndarray) -> np.ndarray:
    """The segment angles at rest with the joints held at ``q`` (B.16 without motion).

    Newton on ``K phi - D^T k o(q) = g G cos phi`` from the undeflected arm.

    Args:
        model: The arm.
        q: Joint angles, rad, shape (n_joints,).

    Returns:
        Segment angles, shape (n,).

    Raises:
        LumpbeamError: Wrong number of angles, or no equilibrium (the links too soft to
            carry their load).
    """
    q = model.check_angles(q)
    try:
        return static_equilibrium(model.chain, tol=1e-12, offsets=model.offsets(q))
    except RuntimeError:
        raise LumpbeamError(
            f'no static equilibrium at q = {q.tolist()}: the links cannot carry their load'
        ) from None


def arm_linear_model(model: ArmModel, q: np.ndarray) -> LinearModel:
    """B.16 linearized about the rest at ``q`` (the joints held: ``q`` is not a coordinate)."""
    return LinearModel.about_equilibrium(model.chain, arm_equilibrium(model, q))


def arm_modes(model: ArmModel, q: np.ndarray) -> Modes:
    """Every underdamped mode about the rest at ``q``, slowest first.

    Frequency ``|lambda| / 2 pi`` and damping ratio ``-Re(lambda) / |lambda|`` of each
    complex eigenvalue pair of the linearized, non-proportionally damped system; overdamped
    (real) modes are left out.

    Args:
        model: The arm.
        q: Joint angles, rad.

    Returns:
        The modes.
    """
    return linear_modes(arm_linear_model(model, q))


def modes_table(modes: Modes) -> list[dict[str, float]]:
    """The modes as ``lumpbeam modes`` lists them in JSON, slowest first.

    Returns:
        One ``{natural_frequency_hz, damping_ratio}`` per underdamped mode.
    """
    return [
        {'natural_frequency_hz': float(f), 'damping_ratio': float(z)}
        for f, z in zip(modes.natural_frequency_hz, modes.damping_ratio, strict=True)
    ]
