"""A rigid transform between two frames (a sensor's frame and ``beam_base``, doc/interfaces.md).

Shared by the sensor comparison (:mod:`lumpbeam_ros.core.compare`), which fits one, and the
synthetic reference tracker (:mod:`lumpbeam_ros.core.synthetic.reference_sensor`), which places
one.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation


@dataclass(frozen=True)
class RigidTransform:
    """``p_target = rotation @ p_source + translation``.

    As the transform from frame ``tracker`` to ``beam_base``, it is the pose of the tracker
    frame in ``beam_base`` (the tf convention: parent ``beam_base``, child ``tracker``).

    Attributes:
        rotation: Proper rotation matrix, ``(3, 3)``.
        translation: ``(3,)``, m.
    """

    rotation: np.ndarray
    translation: np.ndarray

    @classmethod
    def from_euler_deg(
        cls, angles_deg: tuple[float, float, float], translation: tuple[float, float, float]
    ) -> RigidTransform:
        """Builds a transform from extrinsic x-y-z (roll, pitch, yaw) angles in degrees."""
        rotation = Rotation.from_euler('xyz', angles_deg, degrees=True).as_matrix()
        return cls(rotation, np.asarray(translation, dtype=float))

    def apply(self, points: np.ndarray) -> np.ndarray:
        """Maps ``(n, 3)`` points (or one ``(3,)`` point) into the target frame."""
        return np.asarray(np.asarray(points) @ self.rotation.T + self.translation)

    def inverse(self) -> RigidTransform:
        """The transform the other way."""
        rotation = self.rotation.T
        return RigidTransform(rotation, -rotation @ self.translation)

    def quaternion_xyzw(self) -> np.ndarray:
        """The rotation as a unit quaternion ``(x, y, z, w)`` with ``w >= 0`` (ROS order)."""
        quat: np.ndarray = Rotation.from_matrix(self.rotation).as_quat()
        return -quat if quat[3] < 0.0 else quat

    def angle_to(self, other: RigidTransform) -> float:
        """The angle of the rotation between the two transforms' rotations, rad."""
        relative = self.rotation @ other.rotation.T
        return float(np.linalg.norm(Rotation.from_matrix(relative).as_rotvec()))
