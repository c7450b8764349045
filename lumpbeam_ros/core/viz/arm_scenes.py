"""Markers of a recorded arm: the model moved along a bag's joint angles, beside its tip.

A bag of a real arm holds ``/joint_states`` (its encoders) and ``/tip_pose`` (the camera) but
no ``/beam_markers``. :func:`recorded_arm_markers` draws it for ``lumpbeam view --arm``: the
arm model of an arm file follows the recorded angles (linear between the joint states, at
rest in its static equilibrium at the first) through
:func:`~lumpbeam_ros.core.model.arm.simulate.simulate_arm`, and each array shows that model's arm
link by link, its tip, and the measured tip of the latest ``/tip_pose`` within 0.5 s.
"""

from __future__ import annotations

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import (
    BEAM_MARKERS,
    JOINT_STATE_TYPE,
    JOINT_STATES,
    MARKER_ARRAY,
    MARKERS_RATE_HZ,
    POSE_STAMPED,
    TIP_POSE,
)
from lumpbeam_ros.core.bagio import BagReader, convert
from lumpbeam_ros.core.bagio.reader import RawMessage
from lumpbeam_ros.core.model.arm.config import ArmConfig
from lumpbeam_ros.core.model.arm.drive import SampledMotion
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory, default_joint_names
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.simulate import simulate_arm
from lumpbeam_ros.core.viz.marker_messages import scene_cdr
from lumpbeam_ros.core.viz.markers import (
    MEASURED_MAX_AGE_S,
    BeamScene,
    TipPoint,
    lifetime_for_rate,
    marker_sample_indices,
)


def _joint_trajectory(reader: BagReader, config: ArmConfig) -> JointTrajectory:
    """The bag's joint states as a trajectory in the arm's joint order."""
    wanted = list(default_joint_names(config.n_joints))
    times: list[int] = []
    rows: list[np.ndarray] = []
    for _, msg in reader.messages(JOINT_STATES, JOINT_STATE_TYPE):
        stamp_ns, names, positions = convert.joint_state_values(msg)
        if sorted(names) != sorted(wanted) or positions.size != len(names):
            raise LumpbeamError(
                f'{reader.path}: {JOINT_STATES} names {names}, the arm has {wanted}'
            )
        if times and stamp_ns <= times[-1]:
            continue  # a repeated or older state: the motion is a function of time
        times.append(stamp_ns)
        rows.append(positions[[names.index(n) for n in wanted]])
    if len(times) < 2:
        raise LumpbeamError(f'{reader.path}: fewer than 2 {JOINT_STATES} messages')
    return JointTrajectory(
        np.array(times, dtype=float) / convert.NS_PER_S, np.array(rows), tuple(wanted)
    )


def recorded_arm_markers(
    reader: BagReader, config: ArmConfig, rate_hz: float = MARKERS_RATE_HZ
) -> list[RawMessage]:
    """``/beam_markers`` of the arm model moved along a bag's joint angles.

    Args:
        reader: A bag with ``/joint_states`` (``joint_1`` ... ``joint_n``) and, optionally,
            ``/tip_pose``.
        config: The arm.
        rate_hz: Arrays per second.

    Returns:
        The arrays as serialized messages, logged at their stamps, in time order.

    Raises:
        BagError: The bag cannot be read or has no ``/joint_states``.
        LumpbeamError: Joint names other than the arm's, fewer than 2 joint states, or a
            simulation that failed.
    """
    if JOINT_STATES not in reader.topics:
        raise LumpbeamError(f"{reader.path}: no {JOINT_STATES}: not an arm's bag")
    trajectory = _joint_trajectory(reader, config)
    model = ArmModel.from_config(config)
    stamps = trajectory.time_s[marker_sample_indices(trajectory.time_s, rate_hz)]
    motion = simulate_arm(model, SampledMotion(trajectory), stamps)
    tips = []
    if TIP_POSE in reader.topics:
        for _, msg in reader.messages(TIP_POSE, POSE_STAMPED):
            p = msg.pose.position
            tips.append((convert.time_ns(msg.header.stamp), float(p.x), float(p.z)))
    tips.sort()
    tip_times = np.array([t for t, _, _ in tips], dtype=np.int64)
    lifetime = lifetime_for_rate(rate_hz)
    link_starts = tuple(int(k) for k in model.link_starts)
    arrays = []
    for i, stamp in enumerate(stamps):
        stamp_ns = convert.seconds_to_ns(float(stamp))
        measured = None
        latest = int(np.searchsorted(tip_times, stamp_ns, side='right')) - 1
        if latest >= 0 and stamp_ns - tip_times[latest] <= MEASURED_MAX_AGE_S * 1e9:
            measured = TipPoint(tips[latest][1], tips[latest][2])
        scene = BeamScene(
            model.chain.segment_lengths,
            phi=motion.phi[i],
            measured=measured,
            predicted=TipPoint(float(motion.tip_x[i]), float(motion.tip_z[i])),
            link_starts=link_starts,
        )
        data = scene_cdr(scene, stamp_ns, lifetime)
        arrays.append(RawMessage(BEAM_MARKERS, MARKER_ARRAY, stamp_ns, data))
    return arrays
