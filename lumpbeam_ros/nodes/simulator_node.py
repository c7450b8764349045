"""The simulator node: the lumped beam in step with the node's clock, on ``/tip_pose_predicted``.

Subscribes ``/tip_load`` (std_msgs/Float64, kg; reliable, transient local, depth 1 as
:mod:`lumpbeam_ros.core.bagio.qos` says) and ``/beam_params`` (diagnostic_msgs/DiagnosticArray);
publishes ``/tip_pose_predicted`` (geometry_msgs/PoseStamped in ``beam_base``). A steady
timer advances a :class:`~lumpbeam_ros.core.model.stream.PredictionStream` to the node's clock
(wall time, or ``/clock`` with ``use_sim_time``) and publishes the samples due since the last
tick, each stamped with its model time. Another, at ``markers_rate_hz``, publishes
``/beam_markers`` (visualization_msgs/MarkerArray, :mod:`lumpbeam_ros.core.viz.markers`): the
model's latest shape, its tip, the last ``/tip_pose`` it received, the load and the board.
With ``arm_config`` naming an arm file (doc/arm.md) the node simulates the flexible arm
instead (:class:`ArmMode`): it follows the JointTrajectory commands of ``arm_commands``
(``/joint_trajectory`` or ``/joint_trajectory_shaped``) through
:class:`~lumpbeam_ros.core.model.arm.stream.ArmStream` and publishes ``/joint_states`` (the
commanded angles), ``/tip_pose_predicted`` (the last link's free end) and the whole arm on
``/beam_markers``. A command is refused with a throttled warning, and the prediction left as
it was, when it names a joint the arm does not have or not every joint once, has a point
without one position per joint, a position or time that is not finite, times that do not
increase, or a first point at time 0 away from the joints' angles. A command stamped 0 (or
in the past) starts at the node's present, one stamped in the future at its stamp.
Parameters: :data:`~lumpbeam_ros.nodes.params.simulator_params.SIMULATOR_SCHEMA`
(``doc/parameters.md``); their defaults are the values of ``config/simulator.yaml``, where
each is documented.

Run it::

    simulator_node --ros-args --params-file config/simulator.yaml -p use_sim_time:=true
    simulator_node --ros-args -p arm_config:=config/arm_3link.yaml
"""

from __future__ import annotations

import math
import sys
from collections.abc import Mapping, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any, Unpack

import numpy as np
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import PoseStamped
from rclpy.clock import Clock, ClockType
from rclpy.parameter import Parameter
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64
from trajectory_msgs.msg import JointTrajectory as JointTrajectoryMsg
from visualization_msgs.msg import MarkerArray

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import (
    BASE_FRAME,
    BEAM_MARKERS,
    BEAM_PARAMS,
    IDENTIFIER_STATUS,
    JOINT_STATES,
    TIP_LOAD,
    TIP_POSE,
    TIP_POSE_PREDICTED,
)
from lumpbeam_ros.core.bagio.convert import (
    NS_PER_S,
    joint_state,
    pitch_to_quaternion,
    seconds_to_ns,
    time_ns,
)
from lumpbeam_ros.core.bagio.typestore import serialize
from lumpbeam_ros.core.model.adopt import adopt_identified
from lumpbeam_ros.core.model.arm.config import load_arm_config
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.simulate import ArmMotion
from lumpbeam_ros.core.model.arm.stream import ArmStream
from lumpbeam_ros.core.model.parameters import EFFECT_PARAMETERS, BeamParameters, load_beam_config
from lumpbeam_ros.core.model.statics import static_tip_deflection
from lumpbeam_ros.core.model.stream import PredictionStream
from lumpbeam_ros.core.model.trajectory import TipTrajectory
from lumpbeam_ros.core.vision.config import load_camera_config
from lumpbeam_ros.core.vision.placement import board_placement
from lumpbeam_ros.core.viz.marker_messages import scene_cdr
from lumpbeam_ros.core.viz.markers import (
    MEASURED_MAX_AGE_S,
    BeamScene,
    BoardPlacement,
    TipPoint,
    lifetime_for_rate,
)
from lumpbeam_ros.nodes.endpoints import publisher, subscription
from lumpbeam_ros.nodes.lifecycle import run_node
from lumpbeam_ros.nodes.params.simulator_params import SIMULATOR_SCHEMA, effect_parameter_name
from lumpbeam_ros.nodes.ros_parameters import NodeOptions, SchemaNode
from lumpbeam_ros.nodes.trajectory_messages import command_from_msg

#: DiagnosticStatus.OK as a number (rclpy gives levels as one byte).
OK_LEVEL = 0
#: A throttled warning repeats at most this often, s.
WARN_PERIOD_S = 5.0


def load_beam(path: str) -> BeamParameters:
    """Reads the beam of ``beam_config`` (empty: the package's ``paper_beam.yaml``).

    Raises:
        ConfigError: The file is missing or malformed.
    """
    beam, _ = load_beam_config(Path(path) if path else None)
    return beam


def load_board(path: str) -> BoardPlacement:
    """Reads the board of ``camera_config`` (empty: the package's ``camera.yaml``).

    Raises:
        ConfigError: The file is missing or malformed.
    """
    return board_placement(load_camera_config(path or None))


class SimulatorNode(SchemaNode):
    """Publishes the predicted tip pose of the lumped beam under the live tip load.

    Args:
        **options: See :class:`~lumpbeam_ros.nodes.ros_parameters.NodeOptions`.

    Raises:
        ConfigError: The beam file is missing or malformed, or a parameter is of the wrong
            type or out of range.
    """

    def __init__(self, **options: Unpack[NodeOptions]):
        super().__init__(SIMULATOR_SCHEMA, self._on_change, **options)
        values = self.parameter_values
        self._settings = values
        #: The arm being simulated (``arm_config`` given), else ``None``: the clamped beam.
        self.arm: ArmMode | None = None
        self.published = 0
        self.markers_published = 0
        if values['arm_config']:
            self.arm = ArmMode(self, values)
            return
        self._base_beam = load_beam(values['beam_config'])
        self._stream: PredictionStream | None = None
        self._load_kg = float(values['initial_load_kg'])
        self._load_seen = False
        self._adopted: tuple[float, float] | None = None
        self._adopted_beam: BeamParameters | None = None
        self._board = load_board(values['camera_config'])
        self._latest: TipTrajectory | None = None  # the last samples published
        self._measured: tuple[float, TipPoint] | None = None  # stamp, tip of /tip_pose
        self._markers_stamp = -math.inf
        #: Poses published on ``/tip_pose_predicted``, marker arrays on ``/beam_markers``.
        self.published = 0
        self.markers_published = 0
        # Parameters from --params-file, -p and the overrides.
        self._with_effect_parameters(self._base_beam, set(self._parameter_overrides))

        # A late tick publishes several periods' samples in one burst: the stream profile's
        # history holds them (lumpbeam_ros.core.bagio.qos).
        self._pose_out = publisher(self, PoseStamped, TIP_POSE_PREDICTED)
        subscription(self, Float64, TIP_LOAD, self._on_load)
        subscription(self, DiagnosticArray, BEAM_PARAMS, self._on_beam_params)
        self._markers_out = publisher(self, MarkerArray, BEAM_MARKERS)
        subscription(self, PoseStamped, TIP_POSE, self._on_measured)
        # A steady timer: under use_sim_time the node must notice a stalled or jumping /clock,
        # which a timer on that clock would not fire to see.
        self._steady = Clock(clock_type=ClockType.STEADY_TIME)
        self._timer = self._make_timer(values['tick_rate_hz'])
        self._markers_timer = self._make_markers_timer(values['markers_rate_hz'])
        sim = self.get_parameter('use_sim_time').value
        self.get_logger().info(
            f'simulator ready: n_s={self._base_beam.n_segments}, '
            f'{values["rate_hz"]:g} Hz, {"sim" if sim else "wall"} time'
        )

    # -- public state, for tests and tools ----------------------------------------------------

    @property
    def beam(self) -> BeamParameters:
        """The beam being simulated now (the adopted one when adopting)."""
        return self._adopted_beam or self._base_beam

    @property
    def stream(self) -> PredictionStream | None:
        """The running simulation; ``None`` until the clock has started."""
        return self._stream

    # -- callbacks ----------------------------------------------------------------------------

    def _tick(self) -> None:
        now = self._now()
        stream = self._stream
        if stream is None:
            if now > 0.0:  # zero: under use_sim_time, no /clock yet
                self._start(now)
            return
        if now < stream.time - self._settings['reset_jump_back_s']:
            self.get_logger().info(
                f'clock jumped back from {stream.time:.3f} s to {now:.3f} s: '
                f'restarting at rest with {stream.load_kg:g} kg'
            )
            stream.reset(now)
            return
        if now - stream.time > self._settings['max_catch_up_s']:
            self.get_logger().warning(
                f'clock jumped ahead by {now - stream.time:.3f} s: restarting at rest'
            )
            stream.reset(now)
            return
        self._publish(stream.advance_to(now))

    def _on_load(self, msg: Float64) -> None:
        kg = float(msg.data)
        if not math.isfinite(kg) or kg < 0.0:
            self.get_logger().warning(
                f'ignoring /tip_load of {kg!r} kg: not a mass', throttle_duration_sec=WARN_PERIOD_S
            )
            return
        if not _carries(self.beam, kg):
            self.get_logger().warning(
                f'ignoring /tip_load of {kg:g} kg: the beam has no static equilibrium under it '
                f'(cannot carry it); keeping {self._load_kg:g} kg',
                throttle_duration_sec=WARN_PERIOD_S,
            )
            return
        first = not self._load_seen
        self._load_seen = True
        changed = kg != self._load_kg
        self._load_kg = kg
        if self._stream is None:
            return  # the stream starts with it
        if first:
            # The first reading says what has been hanging there all along, not a change.
            self._stream.reset(max(self._now(), self._stream.time), kg)
        elif changed:
            self._stream.set_load(self._now(), kg)

    def _on_measured(self, msg: PoseStamped) -> None:
        p = msg.pose.position
        tip = TipPoint(float(p.x), float(p.z))
        if msg.header.frame_id != BASE_FRAME or not tip.is_finite():
            self.get_logger().warning(
                f'ignoring /tip_pose in frame {msg.header.frame_id!r} at {tip}',
                throttle_duration_sec=WARN_PERIOD_S,
            )
            return
        self._measured = (msg.header.stamp.sec + msg.header.stamp.nanosec / NS_PER_S, tip)

    def _publish_markers(self) -> None:
        latest = self._latest
        if latest is None or self._stream is None or latest.t[-1] == self._markers_stamp:
            return  # nothing simulated yet, or nothing new since the last array
        stamp = float(latest.t[-1])
        measured = None
        if self._measured is not None and abs(self._measured[0] - stamp) <= MEASURED_MAX_AGE_S:
            measured = self._measured[1]
        scene = BeamScene(
            self._stream.beam.segment_length_m,
            phi=None if latest.q is None else latest.q[-1],
            measured=measured,
            predicted=TipPoint(float(latest.x[-1]), float(latest.z[-1])),
            load_kg=float(latest.load_kg[-1]),
            board=self._board,
        )
        lifetime = lifetime_for_rate(self._settings['markers_rate_hz'])
        self._markers_out.publish(scene_cdr(scene, seconds_to_ns(stamp), lifetime))
        self.markers_published += 1
        self._markers_stamp = stamp

    def _on_beam_params(self, msg: DiagnosticArray) -> None:
        if not self._settings['adopt_identified']:
            return
        for status in msg.status:
            if status.name != IDENTIFIER_STATUS or _level(status) != OK_LEVEL:
                continue
            values = {kv.key: kv.value for kv in status.values}
            try:
                k_total = float(values['stiffness_total_nm_per_rad'])
                zeta = float(values['damping_ratio'])
            except (KeyError, ValueError) as exc:
                self.get_logger().warning(
                    f'ignoring /beam_params: bad or missing {exc}',
                    throttle_duration_sec=WARN_PERIOD_S,
                )
                return
            if (k_total, zeta) == self._adopted:
                return
            try:
                beam = adopt_identified(self._base_beam, k_total, zeta)
            except LumpbeamError as exc:
                self.get_logger().warning(
                    f'ignoring /beam_params: {exc}', throttle_duration_sec=WARN_PERIOD_S
                )
                return
            self._adopted, self._adopted_beam = (k_total, zeta), beam
            if self._stream is not None:
                self._stream.set_beam(beam)
            self.get_logger().info(
                f'adopted k_tE={k_total:.1f} N m/rad, zeta={zeta:.5f} (c_tE={beam.c_total:.4f})'
            )

    def _with_effect_parameters(self, beam: BeamParameters, given: set[str]) -> BeamParameters:
        """The beam with the effect parameters given at start; the others take its values.

        Args:
            beam: The beam file's beam.
            given: Parameter names set by ``--params-file``, ``-p`` or the overrides.

        Returns:
            The beam the node runs with.
        """
        effects = beam.effects
        from_file = []
        for effect in EFFECT_PARAMETERS:
            name = effect_parameter_name(effect)
            if name in given:
                effects = effects.with_effect(effect, self._settings[name])
            else:
                from_file.append(Parameter(name, value=float(effects.value(effect))))
        beam = replace(beam, effects=effects)
        self._base_beam = beam
        # So that `ros2 param get` shows the effect the beam runs with.
        self.set_parameters(from_file)
        return beam

    def _on_change(self, changes: Mapping[str, Any]) -> str | None:
        """Applies parameter changes the schema accepted; refuses a beam file that fails."""
        if self.arm is not None:
            return 'the arm mode takes its parameters at start only'
        new_beam = None
        effects = {
            effect: float(changes[effect_parameter_name(effect)])
            for effect in EFFECT_PARAMETERS
            if effect_parameter_name(effect) in changes
        }
        if effects:
            problem = self._apply_effects(effects)
            if problem is not None:
                return problem
        try:
            if 'beam_config' in changes:
                new_beam = load_beam(changes['beam_config'])
                new_beam = replace(new_beam, effects=self._base_beam.effects)
            if 'camera_config' in changes:
                self._board = load_board(changes['camera_config'])
        except LumpbeamError as exc:
            return str(exc)
        self._apply(changes, new_beam)
        return None

    # -- helpers ------------------------------------------------------------------------------

    def _apply_effects(self, values: Mapping[str, float]) -> str | None:
        """Switches effects on the running beam, keeping its motion; or says why not."""
        if not hasattr(self, '_markers_stamp'):
            return None  # still in __init__: the beam is built with them
        effects = before = self._base_beam.effects
        for effect, value in values.items():
            effects = effects.with_effect(effect, value)
        self._base_beam = replace(self._base_beam, effects=effects)
        if self._adopted_beam is not None:
            self._adopted_beam = replace(self._adopted_beam, effects=effects)
        if self._stream is not None:
            try:
                self._stream.set_beam(self.beam)
            except ValueError as exc:
                return str(exc)
        shown = ', '.join(f'{k}={v:g}' for k, v in values.items() if v != before.value(k))
        if shown:
            self.get_logger().info(f'effects set: {shown}')
        return None

    def _apply(self, changes: Mapping[str, Any], new_beam: BeamParameters | None) -> None:
        self._settings.update(changes)
        if 'tick_rate_hz' in changes:
            self.destroy_timer(self._timer)
            self._timer = self._make_timer(changes['tick_rate_hz'])
        if 'markers_rate_hz' in changes:
            if self._markers_timer is not None:
                self.destroy_timer(self._markers_timer)
            self._markers_timer = self._make_markers_timer(changes['markers_rate_hz'])
        if 'adopt_identified' in changes and not changes['adopt_identified']:
            self._adopted, self._adopted_beam = None, None
            new_beam = new_beam or self._base_beam
        if new_beam is not None:
            self._base_beam = new_beam
            self._adopted, self._adopted_beam = None, None
        stream = self._stream
        if stream is None:
            return
        if 'rate_hz' in changes:
            stream.rate_hz = float(changes['rate_hz'])
        if new_beam is not None:
            if new_beam.n_segments == stream.beam.n_segments:
                stream.set_beam(new_beam)
            else:
                self._stream = None  # restarts at rest on the next tick with the new chain
        if not self._load_seen and 'initial_load_kg' in changes:
            self._load_kg = float(changes['initial_load_kg'])
            if self._stream is not None:
                self._stream.reset(max(self._now(), self._stream.time), self._load_kg)

    def _start(self, now: float) -> None:
        self._stream = PredictionStream(self.beam, self._load_kg, now, self._settings['rate_hz'])
        self.get_logger().info(f'simulation started at {now:.3f} s with {self._load_kg:g} kg')

    def _make_timer(self, tick_rate_hz: float) -> Any:
        return self.create_timer(1.0 / tick_rate_hz, self._tick, clock=self._steady)

    def _make_markers_timer(self, rate_hz: float) -> Any:
        if rate_hz <= 0.0:
            return None
        return self.create_timer(1.0 / rate_hz, self._publish_markers, clock=self._steady)

    def _now(self) -> float:
        return self.get_clock().now().nanoseconds / NS_PER_S

    def _publish(self, samples: TipTrajectory) -> None:
        if len(samples):
            self._latest = samples
        for i in range(len(samples)):
            msg = PoseStamped()
            msg.header.frame_id = BASE_FRAME
            sec, nanosec = divmod(seconds_to_ns(float(samples.t[i])), NS_PER_S)
            msg.header.stamp.sec, msg.header.stamp.nanosec = sec, nanosec
            msg.pose.position.x = float(samples.x[i])
            msg.pose.position.z = float(samples.z[i])
            q = msg.pose.orientation
            q.x, q.y, q.z, q.w = pitch_to_quaternion(float(samples.pitch[i]))
            self._pose_out.publish(msg)
            self.published += 1


class ArmMode:
    """The simulator node's arm mode: commands in, the arm's prediction out.

    Args:
        node: The node (its clock, logger, endpoints).
        values: Its parameter values.

    Attributes:
        stream: The arm's prediction.
        accepted: Commands followed.
        refused: Commands refused.
        last_refusal: Why the last one was refused.

    Raises:
        ConfigError: The arm file is missing or malformed.
    """

    def __init__(self, node: SimulatorNode, values: Mapping[str, Any]):
        self.node = node
        self.values = values
        config = load_arm_config(values['arm_config'])
        self.model = ArmModel.from_config(config)
        self.stream = ArmStream(
            self.model, values['rate_hz'], values['arm_ring_down_s'], values['arm_history_s']
        )
        self.accepted = 0
        self.refused = 0
        self.last_refusal = ''
        self.joint_states_published = 0
        self._lengths = self.model.chain.segment_lengths
        self._link_starts = tuple(int(k) for k in self.model.link_starts)
        self._board = load_board(values['camera_config']) if values['camera_config'] else None
        self._latest: ArmMotion | None = None
        self._measured: tuple[float, TipPoint] | None = None
        self._markers_stamp = -math.inf
        self._time = -math.inf  # the clock at the last tick
        self._pose_out = publisher(node, PoseStamped, TIP_POSE_PREDICTED)
        self._joints_out = publisher(node, JointState, JOINT_STATES)
        self._markers_out = publisher(node, MarkerArray, BEAM_MARKERS)
        topic = values['arm_commands']
        subscription(node, JointTrajectoryMsg, topic, self._on_command)
        subscription(node, PoseStamped, TIP_POSE, self._on_measured)
        steady = Clock(clock_type=ClockType.STEADY_TIME)
        node.create_timer(1.0 / values['tick_rate_hz'], self._tick, clock=steady)
        if values['markers_rate_hz'] > 0.0:
            period = 1.0 / values['markers_rate_hz']
            node.create_timer(period, self._publish_markers, clock=steady)
        node.get_logger().info(
            f'simulator ready: {config.n_joints}-link arm ({self.model.chain.n} segments) from '
            f'{values["arm_config"]}, following {topic}, {values["rate_hz"]:g} Hz'
        )

    def _now(self) -> float:
        return float(self.node.get_clock().now().nanoseconds / NS_PER_S)

    def _warn(self, text: str) -> None:
        self.node.get_logger().warning(text, throttle_duration_sec=WARN_PERIOD_S)

    def _on_command(self, msg: JointTrajectoryMsg) -> None:
        now = self._now()
        try:
            command = command_from_msg(msg)
            start = max(command.stamp_s, now) if command.stamp_s > 0.0 else now
            self.stream.command(command.joint_names, command.time_s, command.positions_rad, start)
        except LumpbeamError as exc:
            self.refused += 1
            self.last_refusal = str(exc)
            self._warn(
                f'{self.values["arm_commands"]}: command refused ({exc}); '
                f'{self.refused} refused so far'
            )
            return
        self.accepted += 1
        self.node.get_logger().info(
            f'following a command of {command.time_s.size} points from {start:.3f} s '
            f'({command.time_s[-1]:.3f} s long)'
        )

    def _on_measured(self, msg: PoseStamped) -> None:
        p = msg.pose.position
        tip = TipPoint(float(p.x), float(p.z))
        if msg.header.frame_id != BASE_FRAME or not tip.is_finite():
            self._warn(f'ignoring /tip_pose in frame {msg.header.frame_id!r} at {tip}')
            return
        self._measured = (time_ns(msg.header.stamp) / NS_PER_S, tip)

    def _tick(self) -> None:
        now = self._now()
        if now <= 0.0:
            return  # under use_sim_time, no /clock yet
        jumped_back = now < self._time - self.values['reset_jump_back_s']
        jumped_ahead = now - self._time > self.values['max_catch_up_s']
        if self.stream.started and self._time > 0.0 and (jumped_back or jumped_ahead):
            self.node.get_logger().info(
                f'clock jumped from {self._time:.3f} s to {now:.3f} s: the arm restarts at rest'
            )
            self.stream.restart_at(now)
        self._time = now
        try:
            samples = self.stream.advance_to(now)
        except LumpbeamError as exc:
            self._warn(f'arm simulation failed: {exc}')
            return
        if samples.t.size:
            self._latest = samples
        for i in range(samples.t.size):
            self._publish(samples, i)

    def _publish(self, samples: ArmMotion, i: int) -> None:
        stamp_ns = seconds_to_ns(float(samples.t[i]))
        msg = PoseStamped()
        msg.header.frame_id = BASE_FRAME
        msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(stamp_ns, NS_PER_S)
        msg.pose.position.x = float(samples.tip_x[i])
        msg.pose.position.z = float(samples.tip_z[i])
        q = msg.pose.orientation
        q.x, q.y, q.z, q.w = pitch_to_quaternion(float(samples.tip_pitch[i]))
        self._pose_out.publish(msg)
        self.node.published += 1
        self._joints_out.publish(
            serialize(joint_state(stamp_ns, self.stream.joint_names, samples.q[i]))
        )
        self.joint_states_published += 1

    def _publish_markers(self) -> None:
        latest = self._latest
        if latest is None or latest.t[-1] == self._markers_stamp:
            return
        stamp = float(latest.t[-1])
        measured = None
        if self._measured is not None and abs(self._measured[0] - stamp) <= MEASURED_MAX_AGE_S:
            measured = self._measured[1]
        scene = BeamScene(
            self._lengths,
            phi=latest.phi[-1],
            measured=measured,
            predicted=TipPoint(float(latest.tip_x[-1]), float(latest.tip_z[-1])),
            board=self._board,
            link_starts=self._link_starts,
        )
        lifetime = lifetime_for_rate(self.values['markers_rate_hz'])
        self._markers_out.publish(scene_cdr(scene, seconds_to_ns(stamp), lifetime))
        self.node.markers_published += 1
        self._markers_stamp = stamp


def _carries(beam: BeamParameters, load_kg: float) -> bool:
    """Whether the beam has a static equilibrium under ``load_kg`` at its tip."""
    try:
        # A load the floats cannot carry either (1e308 kg) overflows in the solver: that is
        # a "no", not a numpy warning in the node's log.
        with np.errstate(over='raise', invalid='raise'):
            static_tip_deflection(beam, load_kg)
    except (RuntimeError, ValueError, ArithmeticError):
        return False
    return True


def _level(status: DiagnosticStatus) -> int:
    level = status.level
    return level[0] if isinstance(level, bytes) else int(level)


def _published(node: SimulatorNode) -> dict[str, int]:
    counts = {TIP_POSE_PREDICTED: node.published, BEAM_MARKERS: node.markers_published}
    if node.arm is not None:
        counts[JOINT_STATES] = node.arm.joint_states_published
    return counts


def main(args: Sequence[str] | None = None) -> int:
    """Runs the simulator node until Ctrl-C (console script ``simulator_node``).

    Args:
        args: Command-line arguments (``--ros-args ...``); ``sys.argv`` when ``None``.

    Returns:
        0 after a clean stop, 2 for a bad parameter or beam file.
    """
    return run_node(
        SIMULATOR_SCHEMA.node,
        SimulatorNode,
        _published,
        args,
    )


if __name__ == '__main__':
    sys.exit(main())
