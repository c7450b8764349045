"""Rigid transforms of the camera rig: tip pose, camera mount and board pose.

Frame ``beam_base`` (doc/interfaces.md): x along the undeformed beam, z up, y = z cross x. The
tip moves in the x-z plane; its pitch is a rotation about +y (positive: the tip points
down). The camera is rigidly mounted on the tip; the checkerboard is fixed in ``beam_base``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def rotation_rpy(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """Returns the rotation ``Rz(yaw) Ry(pitch) Rx(roll)`` (the URDF / REP-103 convention).

    Args:
        roll: Angle about x, rad.
        pitch: Angle about y, rad.
        yaw: Angle about z, rad.

    Returns:
        A 3x3 rotation matrix.
    """
    return np.asarray(rotation_z(yaw) @ rotation_y(pitch) @ rotation_x(roll))


def rotation_x(angle: float) -> np.ndarray:
    """Returns the rotation by ``angle`` (rad) about +x."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rotation_y(angle: float) -> np.ndarray:
    """Returns the rotation by ``angle`` (rad) about +y: a positive tip pitch points x down."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rotation_z(angle: float) -> np.ndarray:
    """Returns the rotation by ``angle`` (rad) about +z."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


@dataclass(frozen=True)
class Transform:
    """A rigid transform ``p_parent = rotation @ p_child + translation``.

    Attributes:
        rotation: 3x3 rotation matrix (child axes in the parent frame).
        translation: Child origin in the parent frame, m.
    """

    rotation: np.ndarray
    translation: np.ndarray

    @staticmethod
    def from_xyz_rpy(
        xyz: tuple[float, float, float], rpy: tuple[float, float, float]
    ) -> Transform:
        """Builds a transform from a position and roll-pitch-yaw angles (URDF convention).

        Args:
            xyz: Child origin in the parent frame, m.
            rpy: Roll, pitch, yaw of the child frame, rad.

        Returns:
            The transform.
        """
        return Transform(rotation_rpy(*rpy), np.asarray(xyz, dtype=float))

    def inverse(self) -> Transform:
        """Returns the transform from parent to child."""
        rt = self.rotation.T
        return Transform(rt, -rt @ self.translation)

    def __matmul__(self, other: Transform) -> Transform:
        return Transform(
            self.rotation @ other.rotation, self.rotation @ other.translation + self.translation
        )

    def apply(self, points: np.ndarray) -> np.ndarray:
        """Maps child-frame points (N x 3) into the parent frame."""
        return np.asarray(points @ self.rotation.T + self.translation)


def tip_transform(x: float, z: float, pitch: float) -> Transform:
    """Returns the tip frame in ``beam_base`` for an in-plane tip pose.

    Args:
        x: Tip position along the beam, m.
        z: Vertical tip position, m.
        pitch: Tip slope about +y, rad.

    Returns:
        ``T_base_tip``.
    """
    return Transform(rotation_y(pitch), np.array([x, 0.0, z]))


def tip_pose_from_transform(base_tip: Transform) -> tuple[float, float, float]:
    """Projects a full 6-DoF tip transform onto the bending plane.

    Args:
        base_tip: ``T_base_tip``.

    Returns:
        ``(x, z, pitch)``; the out-of-plane parts (y, roll, yaw) are dropped.
    """
    r = base_tip.rotation
    return (
        float(base_tip.translation[0]),
        float(base_tip.translation[2]),
        float(np.arctan2(r[0, 2] - r[2, 0], r[0, 0] + r[2, 2])),
    )


def pitch_quaternion(pitch: float) -> tuple[float, float, float, float]:
    """Returns the orientation quaternion ``(x, y, z, w)`` of a tip pitch about +y.

    Args:
        pitch: Tip slope, rad.

    Returns:
        The unit quaternion, in the order of ``geometry_msgs/Quaternion``.
    """
    return (0.0, float(np.sin(pitch / 2.0)), 0.0, float(np.cos(pitch / 2.0)))
