"""The synthetic arm bag of ``lumpbeam synth --arm --trajectory`` (doc/arm.md).

The arm starts at rest in its static equilibrium at the trajectory's first row and follows
it; the record runs on after the move so the free vibration is seen. Written as a rosbag2
MCAP bag: ``/joint_states`` (the commanded angles), ``/tip_pose`` (the last link's free end
with the beam's pose noise) and ``/tip_pose_truth`` (without it), all at the pose rate with
stamps ``time_s`` of the trajectory (the first message at its first row), and
``/beam_markers`` (the true arm, link by link, and the measured tip, at 30 Hz).

With images, a camera on the tip films the checkerboard (``/camera/image_raw``,
``/camera/camera_info``, one frame per pose). The board hangs where the camera sees it once
the arm has stopped: :func:`board_at_rest` puts it on the wall across from the tip at the
arm's static equilibrium at the trajectory's last row, turned by the tip's pitch there, so
that the camera sees it centred and upright as the beam rig's camera sees its board; during
the move it crosses the view or is out of it. The camera file with that board is written
into the bag folder as ``camera.yaml``, for ``lumpbeam track --config``.
"""

from __future__ import annotations

import math
import shutil
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import yaml

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import (
    JOINT_STATES,
    MARKERS_RATE_HZ,
    POSE_RATE_HZ,
    TIP_POSE,
    TIP_POSE_TRUTH,
)
from lumpbeam_ros.base.paramfile import parameter_file
from lumpbeam_ros.core.bagio import BagWriter
from lumpbeam_ros.core.model.arm.config import ArmConfig
from lumpbeam_ros.core.model.arm.drive import SampledMotion
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.simulate import ArmMotion, simulate_arm
from lumpbeam_ros.core.model.arm.statics import arm_equilibrium
from lumpbeam_ros.core.model.trajectory import TipTrajectory
from lumpbeam_ros.core.synthetic.drop_test import PITCH_NOISE_PER_M, check_sample_count
from lumpbeam_ros.core.vision.config import CameraConfig, camera_config_from_parameters
from lumpbeam_ros.core.vision.geometry import rotation_y
from lumpbeam_ros.core.vision.placement import board_placement
from lumpbeam_ros.core.viz.marker_messages import write_scene
from lumpbeam_ros.core.viz.markers import (
    BeamScene,
    TipPoint,
    lifetime_for_rate,
    marker_sample_indices,
)

if TYPE_CHECKING:
    from lumpbeam_ros.core.synthetic.images import ImageOptions

#: The camera file written into an arm bag filmed with images.
CAMERA_FILE = 'camera.yaml'


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
        markers_rate_hz: Rate of ``/beam_markers``, Hz; 0 writes none.
    """

    duration_s: float
    rate_hz: float = POSE_RATE_HZ
    noise_m: float = 20e-6
    seed: int = 0
    markers_rate_hz: float = MARKERS_RATE_HZ


def simulate_arm_record(
    config: ArmConfig, trajectory: JointTrajectory, options: ArmSynthOptions
) -> ArmMotion:
    """The arm along the trajectory at the record's stamps.

    Raises:
        LumpbeamError: The trajectory has the wrong number of joints or leaves a joint's
            limits, the record is shorter than it, or it needs more samples than the drop
            test's limit.
    """
    if trajectory.joint_count != config.n_joints:
        raise LumpbeamError(
            f'the trajectory has {trajectory.joint_count} joints, the arm {config.n_joints}'
        )
    config.check_within_limits(trajectory.angles_rad, 'the trajectory')
    if options.duration_s < trajectory.duration_s:
        raise LumpbeamError(
            f'--duration {options.duration_s:g} s is shorter than the trajectory '
            f'({trajectory.duration_s:g} s)'
        )
    check_sample_count(options.duration_s, {'poses': options.rate_hz})
    count = int(math.floor(options.duration_s * options.rate_hz + 1e-9)) + 1
    t = float(trajectory.time_s[0]) + np.arange(count) / options.rate_hz
    return simulate_arm(ArmModel.from_config(config), SampledMotion(trajectory), t)


def rest_tip_pose(model: ArmModel, q: np.ndarray) -> tuple[float, float, float]:
    """The tip pose ``(x, z, pitch)`` of the arm at rest with its joints held at ``q``."""
    x, z, pitch = model.chain.tip_pose(arm_equilibrium(model, q))
    return float(x), float(z), float(pitch)


def board_at_rest(
    source: str | Path | None, tip: tuple[float, float, float]
) -> tuple[dict[str, Any], CameraConfig]:
    """The camera file with its board across from the tip camera at a tip pose.

    The board keeps its distance from the plane of motion (``board.xyz_m``'s y); its centre
    goes to the tip's x and z and its orientation turns by the tip's pitch about y, so the
    camera at that pose sees it as the beam rig's camera sees its board at rest.

    Args:
        source: The camera parameter file (``None``: the package's ``camera.yaml``).
        tip: The tip pose ``(x, z, pitch)``, m, m, rad.

    Returns:
        The flat parameters (dotted keys) and the configuration they make.

    Raises:
        ConfigError: A bad camera file.
    """
    path, params = parameter_file(source, 'camera.yaml')
    x, z, pitch = tip
    placed = camera_config_from_parameters(params, path)
    rotation = rotation_y(pitch) @ placed.rig.base_board.rotation
    # URDF roll-pitch-yaw of R = Rz(yaw) Ry(pitch) Rx(roll).
    roll = math.atan2(rotation[2, 1], rotation[2, 2])
    turn = math.asin(float(np.clip(-rotation[2, 0], -1.0, 1.0)))
    yaw = math.atan2(rotation[1, 0], rotation[0, 0])
    params = {
        **params,
        'board.xyz_m': [x, float(placed.rig.base_board.translation[1]), z],
        'board.rpy_rad': [roll, turn, yaw],
    }
    return params, camera_config_from_parameters(params, path)


def _write_camera_file(
    path: Path, params: dict[str, Any], tip: tuple[float, float, float]
) -> None:
    """Writes flat camera parameters as a ROS 2 parameter file."""
    nested: dict[str, Any] = {}
    for key, value in params.items():
        *parents, leaf = key.split('.')
        node = nested
        for name in parents:
            node = node.setdefault(name, {})
        node[leaf] = list(value) if isinstance(value, tuple) else value
    header = (
        '# The tip camera of a synthetic arm bag (lumpbeam synth --arm --images): the board\n'
        "# hangs across from the tip at the arm's rest after the move, tip (x, z, pitch) = "
        f'({tip[0]:.6g} m, {tip[1]:.6g} m, {tip[2]:.6g} rad).\n'
        '# Track the bag with: lumpbeam track BAG OUT --config BAG/camera.yaml\n'
    )
    text = yaml.safe_dump({'/**': {'ros__parameters': nested}}, sort_keys=False)
    path.write_text(header + text, encoding='utf-8')


def write_arm_bag(
    out: str | Path,
    config: ArmConfig,
    trajectory: JointTrajectory,
    options: ArmSynthOptions,
    images: ImageOptions | None = None,
) -> ArmMotion:
    """Simulates the arm along the trajectory and writes the bag.

    Args:
        out: The bag folder to create (it must not exist).
        config: The arm.
        trajectory: The joints' commanded angles.
        options: Record length, rate, noise, marker rate.
        images: When given, also the tip camera's frames, its board placed by
            :func:`board_at_rest` (its camera file written as ``OUT/camera.yaml``).

    Returns:
        The simulated motion (the truth).

    Raises:
        LumpbeamError: As :func:`simulate_arm_record`.
        ConfigError: A bad camera file.
        BagError: ``out`` exists or cannot be written.
    """
    if float(trajectory.time_s[0]) < 0.0:
        raise LumpbeamError(
            f'the trajectory starts at {float(trajectory.time_s[0]):g} s: bag stamps cannot '
            'be negative'
        )
    model = ArmModel.from_config(config)
    camera_params = camera = None
    board = None
    if images is not None:
        tip = rest_tip_pose(model, trajectory.angles_rad[-1])
        camera_params, camera = board_at_rest(images.camera_config, tip)
        board = board_placement(camera)
    motion = simulate_arm_record(config, trajectory, options)
    rng = np.random.default_rng(options.seed)
    noise = options.noise_m * rng.standard_normal((3, motion.t.size))
    noise[2] *= PITCH_NOISE_PER_M
    drawn: set[int] = set()
    if options.markers_rate_hz > 0.0:
        drawn = set(marker_sample_indices(motion.t, options.markers_rate_hz).tolist())
        lifetime = lifetime_for_rate(options.markers_rate_hz)
    frames = None
    if camera is not None and images is not None:
        # OpenCV only when filming: the pose-only bag needs none.
        from lumpbeam_ros.core.synthetic.images import ImageStream

        truth = TipTrajectory(
            motion.t, motion.tip_x, motion.tip_z, motion.tip_pitch, np.zeros(motion.t.size)
        )
        frames = ImageStream(truth, images, camera)
    created = not Path(out).exists()  # BagWriter refuses an existing OUT: never removed below
    try:
        with BagWriter(out) as bag:
            for i, stamp in enumerate(motion.t):
                bag.write_joint_state(JOINT_STATES, stamp, trajectory.joint_names, motion.q[i])
                measured = (
                    motion.tip_x[i] + noise[0, i],
                    motion.tip_z[i] + noise[1, i],
                    motion.tip_pitch[i] + noise[2, i],
                )
                bag.write_pose(TIP_POSE, stamp, *measured)
                bag.write_pose(
                    TIP_POSE_TRUTH, stamp, motion.tip_x[i], motion.tip_z[i], motion.tip_pitch[i]
                )
                if i in drawn:
                    scene = BeamScene(
                        model.chain.segment_lengths,
                        phi=motion.phi[i],
                        measured=TipPoint(measured[0], measured[1]),
                        board=board,
                        link_starts=tuple(int(k) for k in model.link_starts),
                    )
                    write_scene(bag, stamp, scene, lifetime)
                if frames is not None:
                    frames.write_next(bag)
        if camera_params is not None:
            _write_camera_file(Path(out) / CAMERA_FILE, camera_params, tip)
    except BaseException:
        # Interrupted or failed: a bag cut short is not the record asked for.
        if created:
            shutil.rmtree(out, ignore_errors=True)
        raise
    return motion
