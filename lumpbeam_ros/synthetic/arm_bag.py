"""The synthetic arm bag of ``lumpbeam synth --arm --trajectory`` (doc/arm.md).

The arm starts at rest in its static equilibrium at the trajectory's first row and follows
it; the record runs on after the move so the free vibration is seen. Written as a rosbag2
MCAP bag: ``/joint_states`` (the commanded angles), ``/tip_pose`` (the last link's free end
with the beam's pose noise) and ``/tip_pose_truth`` (without it), all at the pose rate with
stamps ``time_s`` of the trajectory (the first message at its first row).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lumpbeam_ros.arm.config import ArmConfig
from lumpbeam_ros.arm.drive import SampledMotion
from lumpbeam_ros.arm.model import ArmModel
from lumpbeam_ros.arm.simulate import ArmMotion, simulate_arm
from lumpbeam_ros.bagio import BagWriter
from lumpbeam_ros.errors import LumpbeamError
from lumpbeam_ros.interface import JOINT_STATES, POSE_RATE_HZ, TIP_POSE, TIP_POSE_TRUTH
from lumpbeam_ros.motion.joint_trajectory import JointTrajectory
from lumpbeam_ros.synthetic.drop_test import PITCH_NOISE_PER_M, check_sample_count


@dataclass(frozen=True)
class ArmSynthOptions:
    """What ``lumpbeam synth --arm`` varies.

    Attributes:
        duration_s: Record length from the trajectory's first row, s (at least the
            trajectory's own).
        rate_hz: Rate of every topic, Hz.
        noise_m: Standard deviation of the position noise on ``/tip_pose``, m; the pitch
            gets ``noise_m * PITCH_NOISE_PER_M`` rad.
        seed: Seed of the noise.
    """

    duration_s: float
    rate_hz: float = POSE_RATE_HZ
    noise_m: float = 20e-6
    seed: int = 0


def simulate_arm_record(
    config: ArmConfig, trajectory: JointTrajectory, options: ArmSynthOptions
) -> ArmMotion:
    """The arm along the trajectory at the record's stamps.

    Raises:
        LumpbeamError: The trajectory has the wrong number of joints, the record is shorter
            than it, or it needs more samples than the drop test's limit.
    """
    if trajectory.joint_count != config.n_joints:
        raise LumpbeamError(
            f'the trajectory has {trajectory.joint_count} joints, the arm {config.n_joints}'
        )
    if options.duration_s < trajectory.duration_s:
        raise LumpbeamError(
            f'--duration {options.duration_s:g} s is shorter than the trajectory '
            f'({trajectory.duration_s:g} s)'
        )
    check_sample_count(options.duration_s, {'poses': options.rate_hz})
    count = int(math.floor(options.duration_s * options.rate_hz + 1e-9)) + 1
    t = float(trajectory.time_s[0]) + np.arange(count) / options.rate_hz
    return simulate_arm(ArmModel.from_config(config), SampledMotion(trajectory), t)


def write_arm_bag(
    out: str | Path, config: ArmConfig, trajectory: JointTrajectory, options: ArmSynthOptions
) -> ArmMotion:
    """Simulates the arm along the trajectory and writes the bag.

    Args:
        out: The bag folder to create (it must not exist).
        config: The arm.
        trajectory: The joints' commanded angles.
        options: Record length, rate, noise.

    Returns:
        The simulated motion (the truth).

    Raises:
        LumpbeamError: As :func:`simulate_arm_record`.
        BagError: ``out`` exists or cannot be written.
    """
    if float(trajectory.time_s[0]) < 0.0:
        raise LumpbeamError(
            f'the trajectory starts at {float(trajectory.time_s[0]):g} s: bag stamps cannot '
            'be negative'
        )
    motion = simulate_arm_record(config, trajectory, options)
    rng = np.random.default_rng(options.seed)
    noise = options.noise_m * rng.standard_normal((3, motion.t.size))
    noise[2] *= PITCH_NOISE_PER_M
    with BagWriter(out) as bag:
        for i, stamp in enumerate(motion.t):
            bag.write_joint_state(JOINT_STATES, stamp, trajectory.joint_names, motion.q[i])
            bag.write_pose(
                TIP_POSE,
                stamp,
                motion.tip_x[i] + noise[0, i],
                motion.tip_z[i] + noise[1, i],
                motion.tip_pitch[i] + noise[2, i],
            )
            bag.write_pose(
                TIP_POSE_TRUTH, stamp, motion.tip_x[i], motion.tip_z[i], motion.tip_pitch[i]
            )
    return motion
