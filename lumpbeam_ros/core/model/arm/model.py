"""The arm as one lumped chain: every link's segments in a row, joints as turned clamps.

Segment angles are absolute (about +y of ``beam_base``, positive from +x toward -z), as for
the beam. Joint i's clamp turns with the last segment of link i-1 (for i = 1: with the fixed
base) and the motor sets it ``q_i`` further, so the spring from that clamp to link i's first
segment stretches by ``phi_first - phi_before - q_i``: the chain of
:class:`~lumpbeam_ros.core.model.chain.LumpedChain` with the prescribed offset ``q_i`` on that
spring, whose torque reacts on link i-1's last segment. An ideal stiff servo has no
compliance of its own and its clamp no inertia, so ``q`` enters only through those springs
(and ``q'`` through their dampers). The clamped beam is the one-link arm with ``q_1 = 0``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model.arm.config import ArmConfig
from lumpbeam_ros.core.model.chain import LumpedChain


@dataclass(frozen=True)
class ArmModel:
    """An arm's chain and where its joints sit in it.

    Attributes:
        config: The arm.
        chain: All segments of all links, joint 1 outward.
        link_starts: Index of each link's first segment (and first spring) in the chain.
    """

    config: ArmConfig
    chain: LumpedChain
    link_starts: np.ndarray

    @classmethod
    def from_config(cls, config: ArmConfig) -> ArmModel:
        """Builds the chain: segment masses at their centres, joint masses, the payload.

        A segment's mass sits at its centre with inertia ``m L_s^2 / 12`` (B.15); the joint
        mass of link i > 1 rides on link i-1's free end, joint 1's on the fixed axis is left
        out; the payload sits at the last link's free end.

        Args:
            config: The arm.

        Returns:
            The model.
        """
        lengths = np.concatenate(
            [np.full(link.n_segments, link.segment_length_m) for link in config.links]
        )
        n = lengths.size
        counts = np.array([link.n_segments for link in config.links])
        starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
        seg_masses = np.concatenate([np.asarray(link.segment_masses_kg) for link in config.links])
        # Lever of a point at offset a on segment s: L_j before s, a on s, 0 after.
        before = np.tril(np.ones((n, n)), k=-1) * lengths[None, :]
        levers = [before + np.diag(0.5 * lengths)]
        masses = [seg_masses]
        ends = [(starts[i] - 1, link.joint_mass_kg) for i, link in enumerate(config.links) if i]
        ends.append((n - 1, config.payload_kg))
        for segment, mass in ends:
            if mass > 0.0:
                row = np.where(np.arange(n) <= segment, lengths, 0.0)
                levers.append(row[None, :])
                masses.append(np.array([mass]))
        chain = LumpedChain(
            segment_lengths=lengths,
            masses=np.concatenate(masses),
            levers=np.vstack(levers),
            inertia=seg_masses * lengths**2 / 12.0,
            stiffness=np.concatenate([link.spring_stiffness() for link in config.links]),
            damping=np.concatenate([link.spring_damping() for link in config.links]),
            gravity=config.gravity_mps2,
        )
        return cls(config=config, chain=chain, link_starts=starts)

    @property
    def n_joints(self) -> int:
        """Number of joints (links)."""
        return int(self.link_starts.size)

    def check_angles(self, q: np.ndarray, what: str = 'joint angles') -> np.ndarray:
        """``q`` as floats, shape (..., n_joints), all finite.

        Raises:
            LumpbeamError: The wrong number of joints, or a NaN or infinite angle.
        """
        q = np.asarray(q, dtype=float)
        if q.ndim == 0 or q.shape[-1] != self.n_joints:
            given = 1 if q.ndim == 0 else q.shape[-1]
            raise LumpbeamError(
                f'{what}: the arm has {self.n_joints} joints, got {given} angle(s)'
            )
        if not np.all(np.isfinite(q)):
            raise LumpbeamError(f'{what}: angles must be finite')
        return q

    def offsets(self, q: np.ndarray) -> np.ndarray:
        """The springs' prescribed offsets: ``q_i`` on link i's first spring, else 0.

        Args:
            q: Joint angles (or rates), shape (..., n_joints).

        Returns:
            Shape (..., n_segments).
        """
        q = np.asarray(q, dtype=float)
        o = np.zeros((*q.shape[:-1], self.chain.n))
        o[..., self.link_starts] = q
        return o

    def rigid_angles(self, q: np.ndarray) -> np.ndarray:
        """Segment angles of the undeflected arm at joint angles ``q``."""
        return np.cumsum(self.offsets(q), axis=-1)

    def joint_points(self, phi: np.ndarray) -> np.ndarray:
        """(x, z) of the chain's joints and free end in ``beam_base`` (B.17 chained).

        Args:
            phi: Segment angles, shape (..., n).

        Returns:
            Shape (..., n + 1, 2): the base, every segment's end.
        """
        ls = self.chain.segment_lengths
        steps = np.stack([ls * np.cos(phi), -ls * np.sin(phi)], axis=-1)
        zero = np.zeros((*steps.shape[:-2], 1, 2))
        return np.concatenate([zero, np.cumsum(steps, axis=-2)], axis=-2)
