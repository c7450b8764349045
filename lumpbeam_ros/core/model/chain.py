"""The planar chain of rigid segments: mass distribution, springs, dampers and forces.

The equations of motion are the paper's Newton-Euler form (B.14-B.18) written in the absolute
segment angles ``phi`` of B.17. With ``phi_i`` the pitch of segment ``i`` (positive when it
points downward, doc/interfaces.md) and every mass a point on some segment at a lever ``l_i^p``
from joint ``i``, B.16 collapses to

    M(phi) phi'' + S(phi) phi'^2 + K phi + C phi' = g G cos(phi + tilt) + Q_e(phi, phi'),
    M_ij = A_ij cos(phi_i - phi_j) + I_i delta_ij,   S_ij = A_ij sin(phi_i - phi_j),
    A_ij = sum_p m_p l_i^p l_j^p,                     G_i = sum_p m_p l_i^p,

where ``K = D^T diag(k) D`` and ``C = D^T diag(c) D`` act on the joint angles ``D phi``
(joint 1 against the wall, the others between neighbours: B.10, B.11) and ``Q_e`` holds the
effects of doc/interfaces.md ("Missing effects") that are forces: dry friction, drag and the
cubic term ``-k3 phi_1^3`` of joint 1's spring. ``tilt`` is the clamp's pitch below level
(``mount_tilt``): the segments' angles stay relative to the clamp (``beam_base``), gravity
acts at ``phi + tilt``.

Segments may differ in length (a flexible arm's links). A spring whose clamp is turned by a
motor (an arm's joint, doc/arm.md) stretches by ``(D phi)_j - o_j`` with the prescribed offset
``o_j``; :meth:`LumpedChain.drive_forces` gives the generalized forces ``D^T (k o + c o')`` that
the offsets add to the right-hand side. The clamped beam has no offsets.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from lumpbeam_ros.core.model.parameters import BeamParameters

#: Joint velocity (rad/s) below which Coulomb friction is smoothed: sign(v) ~ tanh(v / eps).
FRICTION_SMOOTHING_RAD_S = 1e-3


def _difference_matrix(n: int) -> np.ndarray:
    """D with ``(D phi)_1 = phi_1`` and ``(D phi)_j = phi_j - phi_{j-1}``: joint angles."""
    return np.eye(n) - np.eye(n, k=-1)


def _frozen(array: np.ndarray) -> np.ndarray:
    """A cached matrix, read-only: every caller shares it."""
    array = np.asarray(array)
    array.setflags(write=False)
    return array


#: ``(cos phi, sin phi)`` of a batch, computed once for several force terms.
Trig = tuple[np.ndarray, np.ndarray]


def trig(phi: np.ndarray) -> Trig:
    """``(cos phi, sin phi)``: the trigonometry every force of a batch shares."""
    return np.cos(phi), np.sin(phi)


@dataclass(frozen=True)
class LumpedChain:
    """A planar chain of ``n`` rigid segments carrying point masses.

    Build one with :meth:`from_beam`; the arrays are not to be modified. The matrices
    derived from them (:attr:`inertia_coupling`, :attr:`stiffness_matrix`, ...) are computed
    once per chain and read-only: a simulation evaluates the forces thousands of times.

    Attributes:
        segment_lengths: Length of each segment, m (L_s for a beam).
        masses: Point masses, kg (segment centres, then tip bodies).
        levers: ``levers[p, i]``: how far mass ``p`` sits along segment ``i`` beyond joint
            ``i`` (L_s for segments before its own, its offset on its own, 0 after).
        inertia: Rotary inertia about each segment's own angle, kg m^2.
        stiffness: Joint stiffnesses, N m/rad.
        damping: Joint dampings, N m s/rad.
        gravity: g, m/s^2.
        coulomb_torque: Dry friction torque at joint 1, N m.
        drag_c_q: Quadratic drag on the tip, N s^2/m^2.
        cubic_stiffness: k3 of joint 1's spring, torque ``k phi_1 + k3 phi_1^3``, N m/rad^3.
        tilt: The clamp's pitch below level, rad.
        preload: Constant generalized forces added to :meth:`generalized_forces` (an arm's
            springs held at fixed joint offsets, :meth:`drive_forces`); ``None``: none.
    """

    segment_lengths: np.ndarray
    masses: np.ndarray
    levers: np.ndarray
    inertia: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    gravity: float
    coulomb_torque: float = 0.0
    drag_c_q: float = 0.0
    cubic_stiffness: float = 0.0
    tilt: float = 0.0
    preload: np.ndarray | None = None

    @classmethod
    def from_beam(cls, beam: BeamParameters, load_kg: float = 0.0) -> LumpedChain:
        """Builds the chain of a beam carrying ``load_kg`` at the tip.

        Each segment has mass ``m_b / n_s`` at its centre and inertia ``m L_s^2 / 12`` about
        it (B.15). The mounted body, the hanging load and any ``added_mass`` effect sit at
        the free end, or at the last segment's centre in the paper's convention. A compliant
        mount (``base_compliance``) is a spring in series with joint 1.

        Args:
            beam: The beam.
            load_kg: Mass hanging at the tip, kg.

        Returns:
            The chain.
        """
        n = beam.n_segments
        ls = beam.segment_length_m
        seg_mass = beam.mass_kg / n
        levers = np.tril(np.full((n, n), ls), k=-1) + np.eye(n) * (0.5 * ls)
        tip_lever = ls if beam.tip_placement == 'free_end' else 0.5 * ls
        tip_mass = beam.tip_mass_kg + load_kg + beam.effects.added_mass_kg
        tip_row = np.full((1, n), ls)
        tip_row[0, -1] = tip_lever
        inertia = np.full(n, seg_mass * ls**2 / 12.0)
        inertia[-1] += beam.tip_inertia_kgm2
        stiffness = beam.joint_stiffness()
        k_base = beam.effects.k_base_nm_per_rad
        if k_base > 0.0:
            stiffness[0] = stiffness[0] * k_base / (stiffness[0] + k_base)
        return cls(
            segment_lengths=np.full(n, ls),
            masses=np.concatenate([np.full(n, seg_mass), [tip_mass]]),
            levers=np.vstack([levers, tip_row]),
            inertia=inertia,
            stiffness=stiffness,
            damping=beam.joint_damping(),
            gravity=beam.gravity_mps2,
            coulomb_torque=beam.effects.coulomb_torque_nm,
            drag_c_q=beam.effects.drag_c_q,
            cubic_stiffness=beam.effects.k3_nm_per_rad3,
            tilt=beam.effects.tilt_rad,
        )

    @property
    def n(self) -> int:
        """Number of segments."""
        return int(self.inertia.size)

    @cached_property
    def inertia_coupling(self) -> np.ndarray:
        """A_ij = sum_p m_p l_i^p l_j^p."""
        return _frozen((self.levers * self.masses[:, None]).T @ self.levers)

    @cached_property
    def gravity_moment(self) -> np.ndarray:
        """G_i = sum_p m_p l_i^p: first moment of the masses beyond each joint."""
        return _frozen(self.masses @ self.levers)

    def gravity_forces(self, phi: np.ndarray, cos_phi: np.ndarray | None = None) -> np.ndarray:
        """``g G cos(phi + tilt)``: the generalized forces of gravity, any batch shape.

        Args:
            phi: Angles.
            cos_phi: ``cos(phi)`` if already computed (used when the clamp is level).
        """
        level = cos_phi if cos_phi is not None and self.tilt == 0.0 else np.cos(phi + self.tilt)
        return np.asarray(self.gravity * self.gravity_moment * level)

    def gravity_stiffness(self, phi: np.ndarray) -> np.ndarray:
        """``g G sin(phi + tilt)``: minus the derivative of :meth:`gravity_forces`."""
        return self.gravity * self.gravity_moment * np.sin(phi + self.tilt)

    def cubic_tangent(self, phi: np.ndarray) -> float:
        """``3 k3 phi_1^2``: the cubic term's contribution to joint 1's tangent stiffness."""
        return 3.0 * self.cubic_stiffness * float(phi[0]) ** 2

    @cached_property
    def stiffness_matrix(self) -> np.ndarray:
        """K = D^T diag(k) D."""
        d = _difference_matrix(self.n)
        return _frozen(d.T @ (self.stiffness[:, None] * d))

    @cached_property
    def damping_matrix(self) -> np.ndarray:
        """C = D^T diag(c) D."""
        d = _difference_matrix(self.n)
        return _frozen(d.T @ (self.damping[:, None] * d))

    def drive_forces(self, offsets: np.ndarray, offset_rates: np.ndarray) -> np.ndarray:
        """``D^T (k o + c o')``: the generalized forces of springs whose clamps are turned.

        A spring's torque is ``-k ((D phi)_j - o_j) - c ((D phi')_j - o'_j)``; the ``-K phi
        - C phi'`` part is in :meth:`generalized_forces`, this is the rest. Through ``D^T``
        the torque acts on the segment after the spring and, reversed, on the one before it
        (an arm's motor reacting on the previous link).

        Args:
            offsets: Prescribed offset of each spring, rad, shape (..., n).
            offset_rates: Their rates, rad/s, same shape.

        Returns:
            The generalized forces, same shape.
        """
        torque = self.stiffness * offsets + self.damping * offset_rates
        return np.asarray(torque @ _difference_matrix(self.n))

    def mass_matrix(self, phi: np.ndarray) -> np.ndarray:
        """M(phi) of B.16 for one configuration (n,)."""
        return np.asarray(
            self.inertia_coupling * np.cos(phi[:, None] - phi[None, :]) + np.diag(self.inertia)
        )

    def tip_pose(self, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Pose of the free end in beam_base (B.17 chained to the end of segment n).

        Args:
            phi: Angles, shape (n,) or (samples, n).

        Returns:
            x, z and pitch of the free end.
        """
        ls = self.segment_lengths
        return (
            (ls * np.cos(phi)).sum(axis=-1),
            -(ls * np.sin(phi)).sum(axis=-1),
            phi[..., -1].copy(),
        )

    def tip_velocity(
        self, phi: np.ndarray, phi_dot: np.ndarray, cs: Trig | None = None
    ) -> np.ndarray:
        """Velocity (vx, vz) of the free end, shape (..., 2); ``cs``: :func:`trig` of phi."""
        ls = self.segment_lengths
        c, s = trig(phi) if cs is None else cs
        return np.stack(
            [
                -(ls * s * phi_dot).sum(axis=-1),
                -(ls * c * phi_dot).sum(axis=-1),
            ],
            axis=-1,
        )

    def effect_forces(
        self, phi: np.ndarray, phi_dot: np.ndarray, friction: bool = True, cs: Trig | None = None
    ) -> np.ndarray:
        """Generalized forces of dry friction and the cubic spring at joint 1, and tip drag.

        Args:
            phi: Angles, shape (..., n).
            phi_dot: Angular velocities, same shape.
            friction: Include the (smoothed) dry friction; a solver that treats its switching
                exactly leaves it out.
            cs: :func:`trig` of ``phi`` if already computed.

        Returns:
            Q_e, same shape.
        """
        q = np.zeros(np.broadcast_shapes(phi.shape, phi_dot.shape))
        if self.cubic_stiffness != 0.0:
            q[..., 0] -= self.cubic_stiffness * phi[..., 0] ** 3
        if friction and self.coulomb_torque > 0.0:
            # Joint 1's angle is phi_1 itself (it turns against the wall).
            q[..., 0] -= self.coulomb_torque * np.tanh(phi_dot[..., 0] / FRICTION_SMOOTHING_RAD_S)
        if self.drag_c_q > 0.0:
            c, s = trig(phi) if cs is None else cs
            v = self.tip_velocity(phi, phi_dot, (c, s))
            force = -self.drag_c_q * np.linalg.norm(v, axis=-1, keepdims=True) * v
            # The free end moves by L_i (-sin phi_i, -cos phi_i) per unit of phi_i.
            ls = self.segment_lengths
            q += -ls * (s * force[..., :1] + c * force[..., 1:])
        return q

    def generalized_forces(
        self, phi: np.ndarray, phi_dot: np.ndarray, friction: bool = True, cs: Trig | None = None
    ) -> np.ndarray:
        """Right-hand side of B.16 for a batch: every force but the inertial ``M phi''``.

        ``-S(phi) phi'^2 + g G cos(phi + tilt) - K phi - C phi' + Q_e``, evaluated with the
        ``cos(a - b) = cos a cos b + sin a sin b`` split so that a batch costs two matrix
        products rather than a batch of n x n matrices.

        Args:
            phi: Angles, shape (..., n).
            phi_dot: Angular velocities, same shape.
            friction: Include the dry friction at joint 1 (see :meth:`effect_forces`).
            cs: :func:`trig` of ``phi`` if already computed.

        Returns:
            The generalized forces, same shape.
        """
        a = self.inertia_coupling
        c, s = trig(phi) if cs is None else cs
        w2 = phi_dot**2
        coriolis = s * ((c * w2) @ a) - c * ((s * w2) @ a)
        return np.asarray(
            -coriolis
            + self.gravity_forces(phi, c)
            - phi @ self.stiffness_matrix
            - phi_dot @ self.damping_matrix
            + self.effect_forces(phi, phi_dot, friction, (c, s))
            + (0.0 if self.preload is None else self.preload)
        )

    def inertial_forces(
        self, phi: np.ndarray, phi_ddot: np.ndarray, cs: Trig | None = None
    ) -> np.ndarray:
        """``M(phi) phi''`` for a batch, without forming the matrices (``cs``: :func:`trig`)."""
        a = self.inertia_coupling
        c, s = trig(phi) if cs is None else cs
        return np.asarray(
            c * ((c * phi_ddot) @ a) + s * ((s * phi_ddot) @ a) + self.inertia * phi_ddot
        )

    def acceleration(self, phi: np.ndarray, phi_dot: np.ndarray) -> np.ndarray:
        """Forward dynamics ``phi'' = M(phi)^-1 Q`` for one configuration (n,)."""
        return np.linalg.solve(self.mass_matrix(phi), self.generalized_forces(phi, phi_dot))

    def energy(self, phi: np.ndarray, phi_dot: np.ndarray) -> np.ndarray:
        """Kinetic plus potential (springs and gravity) energy, J, for a batch."""
        kinetic = 0.5 * (phi_dot * self.inertial_forces(phi, phi_dot)).sum(axis=-1)
        spring = 0.5 * (phi * (phi @ self.stiffness_matrix)).sum(axis=-1)
        spring = spring + 0.25 * self.cubic_stiffness * phi[..., 0] ** 4
        heights = -self.gravity * (self.gravity_moment * np.sin(phi + self.tilt)).sum(axis=-1)
        return np.asarray(kinetic + spring + heights)
