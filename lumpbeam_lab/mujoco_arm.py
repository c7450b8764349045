"""The same arm built in MuJoCo: an independent multibody model for the arm's tests and bench.

Every segment is a MuJoCo body hanging from the previous one by a hinge about +y (MuJoCo's
relative joint coordinates, its own mass matrix, bias forces and gravity), carrying its mass
at its centre with rotary inertia ``m L_s^2 / 12``; joint masses and the payload are welded
point masses. The link springs and dampers are the hinges' ``stiffness`` and ``damping``.

An ideal stiff servo sets the angle of the clamp against the previous link's last segment,
and the massless clamp passes the spring's torque on: so the first hinge of each link is the
spring whose rest angle (MuJoCo's ``qpos_spring``) is the commanded joint angle ``q_i``, and
the damper's ``c q_i'`` is applied as a joint force. Both are set before every step at the
step's midpoint (MuJoCo holds them over the step), which keeps RK4 second-order in the drive.
:meth:`MujocoArm.rollout` runs the same in MuJoCo's own loop (``mujoco.rollout``), the drive
applied as joint forces ``k q + c q'`` on the clamp hinges with their springs' rest angle at
0 (the same forces), so that no Python runs between steps: MuJoCo at its fastest.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, replace

import mujoco
import mujoco.rollout
import numpy as np

from lumpbeam_ros.core.model.arm.config import ArmConfig, arm_from_mapping
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.model.parameters import BeamParameters

Drive = Callable[[float], tuple[np.ndarray, np.ndarray]]
#: ``times -> (q, q')`` for an array of times, one row per time.
Drives = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]

#: Steps per call of :meth:`MujocoArm.rollout`'s loop (bounds the memory of its states).
ROLLOUT_CHUNK = 20_000


def _inertial(mass: float, x: float, iyy: float) -> str:
    # MuJoCo needs positive principal inertias obeying the triangle inequality: a thin rod
    # about y and z, a vanishing one about its axis.
    tiny = 1e-12
    return (
        f'<inertial pos="{x!r} 0 0" mass="{mass!r}" '
        f'diaginertia="{tiny + iyy * 1e-9!r} {iyy + tiny!r} {iyy + tiny!r}"/>'
    )


def arm_mjcf(config: ArmConfig, timestep: float) -> str:
    """The MJCF text of the arm."""
    body = ''
    close = ''
    index = 0
    prev_length = 0.0
    for i, link in enumerate(config.links):
        ls = link.segment_length_m
        k = link.spring_stiffness()
        c = link.spring_damping()
        for j in range(link.n_segments):
            pos = prev_length
            extra = ''
            if j == 0 and i > 0 and link.joint_mass_kg > 0.0:
                extra = (
                    f'<body name="joint_mass_{i}" pos="0 0 0">'
                    f'{_inertial(link.joint_mass_kg, 0.0, 0.0)}</body>'
                )
            m = float(link.segment_masses_kg[j])
            body += (
                f'<body name="s{index}" pos="{pos!r} 0 0">'
                f'<joint name="h{index}" type="hinge" axis="0 1 0" '
                f'stiffness="{float(k[j])!r}" damping="{float(c[j])!r}" armature="0"/>'
                f'{_inertial(m, 0.5 * ls, m * ls**2 / 12.0)}{extra}'
            )
            close += '</body>'
            prev_length = ls
            index += 1
    payload = ''
    if config.payload_kg > 0.0:
        payload = (
            f'<body name="payload" pos="{prev_length!r} 0 0">'
            f'{_inertial(config.payload_kg, 0.0, 0.0)}</body>'
        )
    tip = f'<site name="tip" pos="{prev_length!r} 0 0"/>'
    gravity = config.gravity_mps2
    return (
        '<mujoco><compiler angle="radian"/>'
        f'<option timestep="{timestep!r}" integrator="RK4" gravity="0 0 {-gravity!r}">'
        '<flag contact="disable" constraint="disable"/></option>'
        f'<worldbody>{body}{payload}{tip}{close}</worldbody></mujoco>'
    )


@dataclass
class MujocoArm:
    """The arm in MuJoCo, with its clamps driven.

    Args:
        config: The arm.
        timestep: MuJoCo's step, s.
    """

    config: ArmConfig
    timestep: float = 1e-4
    integrator: str = 'RK4'

    def __post_init__(self) -> None:
        xml = arm_mjcf(self.config, self.timestep)
        xml = xml.replace('integrator="RK4"', f'integrator="{self.integrator}"')
        self.model = mujoco.MjModel.from_xml_string(xml)
        self.data = mujoco.MjData(self.model)
        starts = np.cumsum([0] + [link.n_segments for link in self.config.links])[:-1]
        self.clamps = starts
        self.clamp_damping = np.array([link.spring_damping()[0] for link in self.config.links])
        self.clamp_stiffness = np.array([link.spring_stiffness()[0] for link in self.config.links])
        self.tip = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_SITE, 'tip')

    def set_drive(self, q: np.ndarray, q_dot: np.ndarray) -> None:
        """Turns the clamps to ``q`` with rates ``q_dot``."""
        self.model.qpos_spring[self.clamps] = q
        self.data.qfrc_applied[:] = 0.0
        self.data.qfrc_applied[self.clamps] = self.clamp_damping * q_dot

    def set_absolute(self, phi: np.ndarray, phi_dot: np.ndarray) -> None:
        """Sets the state from absolute segment angles (relative hinge angles in MuJoCo)."""
        self.data.qpos[:] = np.diff(phi, prepend=0.0)
        self.data.qvel[:] = np.diff(phi_dot, prepend=0.0)
        mujoco.mj_forward(self.model, self.data)

    def absolute_angles(self) -> np.ndarray:
        """Absolute segment angles of the current state."""
        return np.cumsum(self.data.qpos)

    def tip_pose(self) -> tuple[float, float, float]:
        """x, z and pitch of the tip site in the world (``beam_base``)."""
        x, _, z = self.data.site_xpos[self.tip]
        rot = self.data.site_xmat[self.tip].reshape(3, 3)
        return float(x), float(z), float(np.arctan2(-rot[2, 0], rot[0, 0]))

    def equilibrium(self, q: np.ndarray, tol: float = 1e-12) -> np.ndarray:
        """Newton on MuJoCo's own static forces (``mj_inverse`` at rest); absolute angles."""
        self.set_drive(q, np.zeros_like(q))
        qpos = np.zeros(self.model.nv)
        qpos[self.clamps] = q
        for _ in range(50):
            residual = self._static_force(qpos)
            jac = np.empty((qpos.size, qpos.size))
            for i in range(qpos.size):
                h = 1e-7
                step = np.zeros_like(qpos)
                step[i] = h
                jac[:, i] = (self._static_force(qpos + step) - self._static_force(qpos - step)) / (
                    2 * h
                )
            update = np.linalg.solve(jac, residual)
            qpos -= update
            if np.max(np.abs(update)) < tol:
                break
        self.data.qpos[:] = qpos
        self.data.qvel[:] = 0.0
        mujoco.mj_forward(self.model, self.data)
        return self.absolute_angles()

    def _static_force(self, qpos: np.ndarray) -> np.ndarray:
        self.data.qpos[:] = qpos
        self.data.qvel[:] = 0.0
        self.data.qacc[:] = 0.0
        mujoco.mj_inverse(self.model, self.data)
        # qfrc_inverse = M qacc + bias - passive - applied: zero at a static equilibrium.
        return np.array(self.data.qfrc_inverse)

    def modal_eigenvalues(self, h: float = 1e-6) -> np.ndarray:
        """Eigenvalues of MuJoCo's dynamics linearized about the current state.

        The continuous-time Jacobian of ``qacc`` (``mj_forward``) in ``qpos`` and ``qvel``
        by central differences (``mjd_transitionFD`` does not take RK4).
        """
        nv = self.model.nv
        qpos0, qvel0 = self.data.qpos.copy(), self.data.qvel.copy()

        def acc(qpos: np.ndarray, qvel: np.ndarray) -> np.ndarray:
            self.data.qpos[:] = qpos
            self.data.qvel[:] = qvel
            mujoco.mj_forward(self.model, self.data)
            return np.array(self.data.qacc)

        a = np.zeros((2 * nv, 2 * nv))
        a[:nv, nv:] = np.eye(nv)
        for i in range(nv):
            e = np.zeros(nv)
            e[i] = h
            a[nv:, i] = (acc(qpos0 + e, qvel0) - acc(qpos0 - e, qvel0)) / (2 * h)
            a[nv:, nv + i] = (acc(qpos0, qvel0 + e) - acc(qpos0, qvel0 - e)) / (2 * h)
        acc(qpos0, qvel0)
        return np.asarray(np.linalg.eigvals(a))

    def run(self, drive: Drive, t_end: float, sample_every: float) -> dict[str, np.ndarray]:
        """Steps to ``t_end`` from the current state at time 0, sampling the tip.

        Args:
            drive: ``t -> (q, q')``.
            t_end: End time, s.
            sample_every: Sampling interval, s (a multiple of the step).

        Returns:
            ``t``, ``x``, ``z``, ``pitch``, ``phi`` at the samples (time 0 included).
        """
        per_sample = round(sample_every / self.timestep)
        count = round(t_end / sample_every) + 1
        rows = []
        step = 0
        for k in range(count):
            while step < k * per_sample:
                self.set_drive(*drive((step + 0.5) * self.timestep))
                mujoco.mj_step(self.model, self.data)
                step += 1
            mujoco.mj_kinematics(self.model, self.data)
            rows.append((k * sample_every, *self.tip_pose(), self.absolute_angles()))
        return {
            't': np.array([r[0] for r in rows]),
            'x': np.array([r[1] for r in rows]),
            'z': np.array([r[2] for r in rows]),
            'pitch': np.array([r[3] for r in rows]),
            'phi': np.array([r[4] for r in rows]),
        }

    def rollout(self, drives: Drives, t_end: float, sample_every: float) -> dict[str, np.ndarray]:
        """As :meth:`run`, in MuJoCo's own loop; the tip from MuJoCo's kinematics.

        Args:
            drives: ``times -> (q, q')`` for an array of times.
            t_end: End time, s.
            sample_every: Sampling interval, s (a multiple of the step).

        Returns:
            ``t``, ``x``, ``z``, ``pitch`` at the samples (time 0 included), and ``wall_s``
            and ``cpu_s``: the seconds spent in MuJoCo's loop alone.
        """
        h = self.timestep
        per_sample = round(sample_every / h)
        count = round(t_end / sample_every) + 1
        total = (count - 1) * per_sample
        self.model.qpos_spring[self.clamps] = 0.0
        spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
        state = np.empty(mujoco.mj_stateSize(self.model, spec))
        self.data.qfrc_applied[:] = 0.0
        mujoco.mj_getState(self.model, self.data, state, spec)
        control = mujoco.mjtState.mjSTATE_QFRC_APPLIED
        qpos = [self.data.qpos.copy()]
        wall = cpu = 0.0
        done = 0
        while done < total:
            steps = min(ROLLOUT_CHUNK, total - done)
            q, q_dot = drives((done + np.arange(steps) + 0.5) * h)
            forces = np.zeros((1, steps, self.model.nv))
            forces[0][:, self.clamps] = self.clamp_stiffness * q + self.clamp_damping * q_dot
            start, start_cpu = time.perf_counter(), time.process_time()
            states, _ = mujoco.rollout.rollout(
                self.model, self.data, state, forces, control_spec=control
            )
            wall += time.perf_counter() - start
            cpu += time.process_time() - start_cpu
            state = states[0, -1]
            first = (-done - 1) % per_sample
            qpos.extend(states[0, first::per_sample, 1 : 1 + self.model.nq])
            done += steps
        rows = []
        for k, pos in enumerate(qpos):
            self.data.qpos[:] = pos
            mujoco.mj_kinematics(self.model, self.data)
            rows.append((k * sample_every, *self.tip_pose()))
        table = np.array(rows)
        return {
            't': table[:, 0],
            'x': table[:, 1],
            'z': table[:, 2],
            'pitch': table[:, 3],
            'wall_s': np.array(wall),
            'cpu_s': np.array(cpu),
        }


def beam_as_arm(beam: BeamParameters) -> ArmConfig:
    """The clamped beam as a one-link arm (its mounted mass the payload at the free end)."""
    link = {
        'length_m': beam.length_m,
        'n_segments': beam.n_segments,
        'k_total_nm_per_rad': beam.k_total_nm_per_rad,
        'mass_kg': beam.mass_kg,
        # The identified damping as a spring-by-spring beta: c_E / k_E (B.13, B.23).
        'damping_beta': beam.beta_identified * beam.c_total / beam.k_total_nm_per_rad,
    }
    return arm_from_mapping({'arm': {'payload_kg': beam.tip_mass_kg, 'links': [link]}}, 'beam')


@dataclass(frozen=True)
class MujocoDrop:
    """The drop test in MuJoCo: tip samples and the unloaded chain's first mode.

    Attributes:
        t: Stamps, s.
        z: Tip z, m.
        pitch: Tip pitch, rad.
        natural_frequency_hz: MuJoCo's first mode about the unloaded equilibrium, Hz.
        damping_ratio: Its damping ratio.
    """

    t: np.ndarray
    z: np.ndarray
    pitch: np.ndarray
    natural_frequency_hz: float
    damping_ratio: float


def mujoco_drop_test(
    beam: BeamParameters, load_kg: float, release_s: float, duration_s: float, rate_hz: float
) -> MujocoDrop:
    """The paper's drop test (section B.3) run in MuJoCo: at rest under ``m_d + m_l``, then free.

    The chain rests at MuJoCo's own equilibrium with the load until ``release_s``; from there
    the unloaded chain swings in MuJoCo's loop with RK4, at a step that divides the sampling
    interval and is at most 1e-4 s (the class's default). At 2e-4 s the explicit step is
    past the stability of the stiffest joint dampers and the first mode runs 10 % fast (at
    3.36 Hz, damped 3.4 times too much) without blowing up; at 1e-4 s and 5e-5 s it is the
    same to 1e-13.
    """
    heavy = MujocoArm(beam_as_arm(replace(beam, tip_mass_kg=beam.tip_mass_kg + load_kg)))
    angles = heavy.equilibrium(np.zeros(1))
    _, z_rest, pitch_rest = heavy.tip_pose()
    interval = 1.0 / rate_hz
    steps = math.ceil(interval / MujocoArm.timestep)
    light = MujocoArm(beam_as_arm(beam), timestep=interval / steps)
    light.equilibrium(np.zeros(1))
    poles = light.modal_eigenvalues()
    first = poles[np.argmin(np.where(poles.imag > 0.0, np.abs(poles), np.inf))]
    light.set_absolute(angles, np.zeros_like(angles))

    def held(times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return np.zeros((times.size, 1)), np.zeros((times.size, 1))

    count = int(np.floor(duration_s * rate_hz + 1e-9)) + 1
    t = np.arange(count) / rate_hz
    resting = t < release_s
    free = light.rollout(held, float(t[-1] - t[~resting][0]), interval)
    return MujocoDrop(
        t,
        np.concatenate([np.full(int(resting.sum()), z_rest), free['z']]),
        np.concatenate([np.full(int(resting.sum()), pitch_rest), free['pitch']]),
        float(abs(first) / (2.0 * math.pi)),
        float(-first.real / abs(first)),
    )


def mujoco_residual(
    config: ArmConfig, trajectory: JointTrajectory, window_s: float, sample_every: float = 2e-3
) -> float:
    """A move's residual vibration in MuJoCo: the tip's RMS distance from MuJoCo's own rest.

    The arm starts at MuJoCo's static equilibrium at the first row and follows the cubic
    spline of the rows (what the arm's model follows for a dense trajectory), run in MuJoCo's
    own loop at a step within RK4's stability on the arm's fastest pole; the window opens at
    the last row.

    Args:
        config: The arm (the truth).
        trajectory: The commanded move, rest to rest.
        window_s: The window after the move, s.
        sample_every: The tip's sampling interval, s.

    Returns:
        The RMS distance over the window, m.
    """
    from scipy.interpolate import CubicSpline

    from lumpbeam_ros.core.model.arm.residual import residual_rms

    start, end = trajectory.time_s[0], trajectory.time_s[-1]
    probe = MujocoArm(config)
    probe.equilibrium(trajectory.angles_rad[-1])
    rest_x, rest_z, _ = probe.tip_pose()
    fastest = float(np.max(np.abs(probe.modal_eigenvalues())))
    step = sample_every / max(20, math.ceil(sample_every * fastest / 2.0))
    spline = CubicSpline(trajectory.time_s - start, trajectory.angles_rad, axis=0)
    duration = end - start

    def drives(times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        moving = (times <= duration)[:, np.newaxis]
        clipped = np.minimum(times, duration)
        q = np.where(moving, spline(clipped), trajectory.angles_rad[-1])
        return q, np.where(moving, spline(clipped, 1), 0.0)

    arm = MujocoArm(config, step)
    arm.equilibrium(trajectory.angles_rad[0])
    run = arm.rollout(drives, duration + window_s, sample_every)
    return residual_rms(run['t'], run['x'], run['z'], (rest_x, rest_z), duration, window_s)
