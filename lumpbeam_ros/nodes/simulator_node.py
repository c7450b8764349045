"""The simulator node: the lumped beam in step with the node's clock, on ``/tip_pose_predicted``.

Subscribes ``/tip_load`` (std_msgs/Float64, kg; reliable, transient local, depth 1 as
:mod:`lumpbeam_ros.core.bagio.qos` says) and ``/beam_params`` (diagnostic_msgs/DiagnosticArray);
publishes ``/tip_pose_predicted`` (geometry_msgs/PoseStamped in ``beam_base``). A steady
timer advances a :class:`~lumpbeam_ros.core.model.stream.PredictionStream` to the node's clock
(wall time, or ``/clock`` with ``use_sim_time``) and publishes the samples due since the last
tick, each stamped with its model time. A load change is dated by when it was sent
(:mod:`~lumpbeam_ros.nodes.sent_time`; under ``use_sim_time`` the node also reads ``/clock``'s
send times for it), and one taken after the model passed that instant is simulated again
from it. Another timer, at ``markers_rate_hz``, publishes
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
in the past) starts at the node's present, one stamped in the future at its stamp. With
``adopt_identified`` the arm's links (or payload) of each ``/arm_params`` status of level OK
replace the file's from the next simulation on.
Parameters: :data:`~lumpbeam_ros.nodes.params.simulator_params.SIMULATOR_SCHEMA`
(``doc/parameters.md``); their defaults are the values of ``config/simulator.yaml``, where
each is documented.

One node, one way of running a model: a steady timer advances the model to the node's clock
and publishes what it predicts, a clock that jumps back (a bag that loops) or far ahead
restarts the model at rest, ``/tip_pose`` is drawn beside the model's tip on
``/beam_markers``. Behind it is the clamped beam (:class:`BeamSimulation`) or the arm
(:class:`ArmSimulation`), each with its own inputs.

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
from rosgraph_msgs.msg import Clock as ClockMsg
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64
from trajectory_msgs.msg import JointTrajectory as JointTrajectoryMsg
from visualization_msgs.msg import MarkerArray

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import (
    ARM_PARAMS,
    ARM_STATUS,
    BASE_FRAME,
    BEAM_MARKERS,
    BEAM_PARAMS,
    CLOCK,
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
from lumpbeam_ros.core.bagio.tipseries import TipSeries
from lumpbeam_ros.core.bagio.typestore import serialize
from lumpbeam_ros.core.ident.arm.learner import arm_from_status
from lumpbeam_ros.core.model.adopt import adopt_identified
from lumpbeam_ros.core.model.arm.config import load_arm_config
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.simulate import ArmMotion
from lumpbeam_ros.core.model.arm.stream import ArmStream
from lumpbeam_ros.core.model.parameters import EFFECT_PARAMETERS, BeamParameters, load_beam_config
from lumpbeam_ros.core.model.statics import carries
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
from lumpbeam_ros.nodes.sent_time import SentClock, sent_ns
from lumpbeam_ros.nodes.trajectory_messages import command_from_msg, command_subscription

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
    """Publishes the predicted tip pose of the lumped beam, or of the arm, as time passes.

    Args:
        **options: See :class:`~lumpbeam_ros.nodes.ros_parameters.NodeOptions`.

    Attributes:
        model: The model behind the node: the beam, or the arm (``arm_config`` given).
        arm: The arm, or ``None`` for the beam.
        published: Poses published on ``/tip_pose_predicted``.
        markers_published: Marker arrays published on ``/beam_markers``.

    Raises:
        ConfigError: The beam, arm or camera file is missing or malformed, or a parameter is
            of the wrong type or out of range.
    """

    def __init__(self, **options: Unpack[NodeOptions]):
        super().__init__(SIMULATOR_SCHEMA, self._on_change, **options)
        values = self.parameter_values
        self._settings = values
        self.published = 0
        self.markers_published = 0
        self._measured: tuple[float, TipPoint] | None = None  # stamp, tip of /tip_pose
        self._markers_stamp = -math.inf
        self._clock_s = -math.inf  # the clock at the last tick
        self.arm: ArmSimulation | None = None
        self.model: BeamSimulation | ArmSimulation
        if values['arm_config']:
            self.model = self.arm = ArmSimulation(self, values)
        else:
            self.model = BeamSimulation(self, values, set(self._parameter_overrides))
        # A late tick publishes several periods' samples in one burst: the stream profile's
        # history holds them (lumpbeam_ros.core.bagio.qos).
        self._pose_out = publisher(self, PoseStamped, TIP_POSE_PREDICTED)
        self._markers_out = publisher(self, MarkerArray, BEAM_MARKERS)
        subscription(self, PoseStamped, TIP_POSE, self._on_measured)
        # A steady timer: under use_sim_time the node must notice a stalled or jumping /clock,
        # which a timer on that clock would not fire to see.
        self._steady = Clock(clock_type=ClockType.STEADY_TIME)
        self._timer = self._make_timer(values['tick_rate_hz'])
        self._markers_timer = self._make_markers_timer(values['markers_rate_hz'])
        sim = self.get_parameter('use_sim_time').value
        self.get_logger().info(
            f'simulating the {self.model.description}, {values["rate_hz"]:g} Hz, '
            f'{"sim" if sim else "wall"} time'
        )

    # -- the beam's state, for tests and tools ------------------------------------------------

    @property
    def beam(self) -> BeamParameters:
        """The beam being simulated now (the adopted one when adopting).

        Raises:
            AttributeError: The node simulates an arm.
        """
        return self._beam().beam

    @property
    def stream(self) -> PredictionStream | None:
        """The beam's running simulation; ``None`` until the clock has started."""
        return self._beam().stream

    def _beam(self) -> BeamSimulation:
        if not isinstance(self.model, BeamSimulation):
            raise AttributeError('the simulator runs an arm, not the clamped beam')
        return self.model

    # -- the one loop -------------------------------------------------------------------------

    def _tick(self) -> None:
        now = self.now()
        if now <= 0.0:
            return  # under use_sim_time, no /clock yet
        last, self._clock_s = self._clock_s, now
        jumped_back = now < last - self._settings['reset_jump_back_s']
        jumped_ahead = now - last > self._settings['max_catch_up_s']
        if math.isfinite(last) and (jumped_back or jumped_ahead) and self.model.restart_at(now):
            self.get_logger().info(
                f'clock jumped from {last:.3f} s to {now:.3f} s: '
                f'the {self.model.name} restarts at rest'
            )
        try:
            predicted = self.model.advance_to(now)
        except LumpbeamError as exc:
            self.get_logger().warning(
                f'{self.model.name} simulation failed: {exc}', throttle_duration_sec=WARN_PERIOD_S
            )
            return
        for i in range(predicted.t.size):
            stamp_ns = seconds_to_ns(float(predicted.t[i]))
            msg = PoseStamped()
            msg.header.frame_id = BASE_FRAME
            msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(stamp_ns, NS_PER_S)
            msg.pose.position.x = float(predicted.x[i])
            msg.pose.position.z = float(predicted.z[i])
            q = msg.pose.orientation
            q.x, q.y, q.z, q.w = pitch_to_quaternion(float(predicted.pitch[i]))
            self._pose_out.publish(msg)
            self.published += 1
            self.model.published(stamp_ns, i)

    def _on_measured(self, msg: PoseStamped) -> None:
        p = msg.pose.position
        tip = TipPoint(float(p.x), float(p.z))
        if msg.header.frame_id != BASE_FRAME or not tip.is_finite():
            self.get_logger().warning(
                f'ignoring /tip_pose in frame {msg.header.frame_id!r} at {tip}',
                throttle_duration_sec=WARN_PERIOD_S,
            )
            return
        self._measured = (time_ns(msg.header.stamp) / NS_PER_S, tip)

    def _publish_markers(self) -> None:
        stamp = self.model.latest_stamp()
        if stamp is None or stamp == self._markers_stamp:
            return  # nothing simulated yet, or nothing new since the last array
        measured = None
        if self._measured is not None and abs(self._measured[0] - stamp) <= MEASURED_MAX_AGE_S:
            measured = self._measured[1]
        lifetime = lifetime_for_rate(self._settings['markers_rate_hz'])
        scene = self.model.scene(measured)
        self._markers_out.publish(scene_cdr(scene, seconds_to_ns(stamp), lifetime))
        self.markers_published += 1
        self._markers_stamp = stamp

    # -- parameters ---------------------------------------------------------------------------

    def _on_change(self, changes: Mapping[str, Any]) -> str | None:
        """Applies parameter changes the schema accepted; refuses a beam file that fails."""
        if not hasattr(self, 'model'):
            return None  # still in __init__: the model is built with them
        problem = self.model.on_change(changes)
        if problem is not None:
            return problem
        self._settings.update(changes)
        if 'tick_rate_hz' in changes:
            self.destroy_timer(self._timer)
            self._timer = self._make_timer(changes['tick_rate_hz'])
        if 'markers_rate_hz' in changes:
            if self._markers_timer is not None:
                self.destroy_timer(self._markers_timer)
            self._markers_timer = self._make_markers_timer(changes['markers_rate_hz'])
        return None

    def _make_timer(self, tick_rate_hz: float) -> Any:
        return self.create_timer(1.0 / tick_rate_hz, self._tick, clock=self._steady)

    def _make_markers_timer(self, rate_hz: float) -> Any:
        if rate_hz <= 0.0:
            return None
        return self.create_timer(1.0 / rate_hz, self._publish_markers, clock=self._steady)

    def now(self) -> float:
        """The node's clock, s (wall time, or ``/clock`` under ``use_sim_time``)."""
        return float(self.get_clock().now().nanoseconds / NS_PER_S)


_NOTHING = TipSeries(*(np.empty(0),) * 4)


class BeamSimulation:
    """The clamped beam behind the simulator node: ``/tip_load`` and ``/beam_params`` in.

    Args:
        node: The node (its clock, logger, endpoints, parameters).
        values: Its parameter values.
        given: The parameters set by ``--params-file``, ``-p`` or the overrides.

    Raises:
        ConfigError: The beam or camera file is missing or malformed.
    """

    name = 'beam'

    def __init__(self, node: SimulatorNode, values: Mapping[str, Any], given: set[str]):
        self.node = node
        self.values = values
        self._base_beam = load_beam(values['beam_config'])
        self.stream: PredictionStream | None = None
        self._load_kg = float(values['initial_load_kg'])
        self._load_seen = False
        self._adopted: tuple[float, float] | None = None
        self._adopted_beam: BeamParameters | None = None
        self._board = load_board(values['camera_config'])
        self._latest: TipTrajectory | None = None  # the last samples published
        self._with_effect_parameters(given)
        self._sent = SentClock(bool(node.get_parameter('use_sim_time').value))
        if self._sent.sim_time:
            subscription(node, ClockMsg, CLOCK, lambda msg, info: self._on_clock(msg, info))
        subscription(node, Float64, TIP_LOAD, lambda msg, info: self._on_load(msg, info))
        subscription(node, DiagnosticArray, BEAM_PARAMS, self._on_beam_params)

    @property
    def description(self) -> str:
        """What the node simulates, for its start-up line."""
        return f'beam of {self._base_beam.n_segments} segments'

    @property
    def beam(self) -> BeamParameters:
        """The beam being simulated now (the adopted one when adopting)."""
        return self._adopted_beam or self._base_beam

    # -- the model's side of the loop ---------------------------------------------------------

    def advance_to(self, now: float) -> TipSeries:
        """The samples due up to ``now``; the first call starts the simulation at rest."""
        if self.stream is None:
            self.stream = PredictionStream(self.beam, self._load_kg, now, self.values['rate_hz'])
            self.node.get_logger().info(
                f'simulation started at {now:.3f} s with {self._load_kg:g} kg'
            )
            return _NOTHING
        samples = self.stream.advance_to(now)
        if len(samples):
            self._latest = samples
        return samples

    def restart_at(self, now: float) -> bool:
        """Restarts at rest under the current load (False: nothing was running)."""
        if self.stream is None:
            return False
        self.stream.reset(now)
        return True

    def published(self, stamp_ns: int, index: int) -> None:
        """Nothing besides the pose is published for a sample of the beam."""

    def latest_stamp(self) -> float | None:
        """The stamp of the last sample published (``None``: none yet)."""
        if self._latest is None or self.stream is None:
            return None
        return float(self._latest.t[-1])

    def scene(self, measured: TipPoint | None) -> BeamScene:
        """The beam's last published sample, drawn."""
        latest = self._latest
        assert latest is not None and self.stream is not None
        return BeamScene(
            self.stream.beam.segment_length_m,
            phi=None if latest.q is None else latest.q[-1],
            measured=measured,
            predicted=TipPoint(float(latest.x[-1]), float(latest.z[-1])),
            load_kg=float(latest.load_kg[-1]),
            board=self._board,
        )

    # -- its inputs ---------------------------------------------------------------------------

    def _on_clock(self, msg: ClockMsg, info: Mapping[str, int]) -> None:
        self._sent.clock_sent(sent_ns(info), time_ns(msg.clock) / NS_PER_S)

    def _on_load(self, msg: Float64, info: Mapping[str, int] | None = None) -> None:
        kg = float(msg.data)
        if not carries(self.beam, kg):
            self.node.refuse(
                TIP_LOAD,
                f'{kg!r} kg refused: not a mass, or one the beam cannot carry (no static '
                'equilibrium, or a sag past a tenth of its length)',
                f'keeping {self._load_kg:g} kg',
            )
            return
        first = not self._load_seen
        self._load_seen = True
        changed = kg != self._load_kg
        self._load_kg = kg
        if self.stream is None:
            return  # the stream starts with it
        if first:
            # The first reading says what has been hanging there all along, not a change.
            self.stream.reset(max(self.node.now(), self.stream.time), kg)
        elif changed:
            # Float64 has no stamp: dated by when it was sent, however late it is delivered.
            self.stream.set_load(self._sent.sent_at(sent_ns(info), self.node.now()), kg)

    def _keeping(self) -> str:
        """What the simulator keeps when it refuses an estimate."""
        if self._adopted is None:
            return "keeping the beam file's stiffness"
        return f'keeping k_tE={self._adopted[0]:.6g} N m/rad'

    def _on_beam_params(self, msg: DiagnosticArray) -> None:
        if not self.values['adopt_identified']:
            return
        for status in msg.status:
            if status.name != IDENTIFIER_STATUS or _level(status) != OK_LEVEL:
                continue
            values = {kv.key: kv.value for kv in status.values}
            try:
                k_total = float(values['stiffness_total_nm_per_rad'])
                zeta = float(values['damping_ratio'])
            except (KeyError, ValueError) as exc:
                self.node.refuse(
                    BEAM_PARAMS, f'estimate refused (bad or missing {exc})', self._keeping()
                )
                return
            if (k_total, zeta) == self._adopted:
                return
            try:
                beam = adopt_identified(self._base_beam, k_total, zeta)
            except LumpbeamError as exc:
                self.node.refuse(BEAM_PARAMS, f'estimate refused ({exc})', self._keeping())
                return
            if not carries(beam, self._load_kg):
                self.node.refuse(
                    BEAM_PARAMS,
                    f'k_tE={k_total:.6g} N m/rad refused: the beam would not carry its '
                    f'{self._load_kg:g} kg load',
                    self._keeping(),
                )
                return
            self._adopted, self._adopted_beam = (k_total, zeta), beam
            if self.stream is not None:
                self.stream.set_beam(beam)
            self.node.get_logger().info(
                f'adopted k_tE={k_total:.1f} N m/rad, zeta={zeta:.5f} (c_tE={beam.c_total:.4f})'
            )

    # -- parameters ---------------------------------------------------------------------------

    def _with_effect_parameters(self, given: set[str]) -> None:
        """The beam with the effect parameters given at start; the others take its values.

        Args:
            given: Parameter names set by ``--params-file``, ``-p`` or the overrides.
        """
        effects = self._base_beam.effects
        from_file = []
        for effect in EFFECT_PARAMETERS:
            name = effect_parameter_name(effect)
            if name in given:
                effects = effects.with_effect(effect, self.values[name])
            else:
                from_file.append(Parameter(name, value=float(effects.value(effect))))
        self._base_beam = replace(self._base_beam, effects=effects)
        # So that `ros2 param get` shows the effect the beam runs with.
        self.node.set_parameters(from_file)

    def on_change(self, changes: Mapping[str, Any]) -> str | None:
        """Applies parameter changes to the beam, or says why not (the beam unchanged)."""
        effects = {
            effect: float(changes[effect_parameter_name(effect)])
            for effect in EFFECT_PARAMETERS
            if effect_parameter_name(effect) in changes
        }
        if effects:
            problem = self._apply_effects(effects)
            if problem is not None:
                return problem
        new_beam = None
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

    def _apply_effects(self, values: Mapping[str, float]) -> str | None:
        """Switches effects on the running beam, keeping its motion; or says why not."""
        effects = before = self._base_beam.effects
        for effect, value in values.items():
            effects = effects.with_effect(effect, value)
        self._base_beam = replace(self._base_beam, effects=effects)
        if self._adopted_beam is not None:
            self._adopted_beam = replace(self._adopted_beam, effects=effects)
        if self.stream is not None:
            try:
                self.stream.set_beam(self.beam)
            except ValueError as exc:
                return str(exc)
        shown = ', '.join(f'{k}={v:g}' for k, v in values.items() if v != before.value(k))
        if shown:
            self.node.get_logger().info(f'effects set: {shown}')
        return None

    def _apply(self, changes: Mapping[str, Any], new_beam: BeamParameters | None) -> None:
        if 'adopt_identified' in changes and not changes['adopt_identified']:
            self._adopted, self._adopted_beam = None, None
            new_beam = new_beam or self._base_beam
        if new_beam is not None:
            self._base_beam = new_beam
            self._adopted, self._adopted_beam = None, None
        stream = self.stream
        if stream is None:
            return
        if 'rate_hz' in changes:
            stream.rate_hz = float(changes['rate_hz'])
        if new_beam is not None:
            if new_beam.n_segments == stream.beam.n_segments:
                stream.set_beam(new_beam)
            else:
                self.stream = None  # restarts at rest on the next tick with the new chain
        if not self._load_seen and 'initial_load_kg' in changes:
            self._load_kg = float(changes['initial_load_kg'])
            if self.stream is not None:
                self.stream.reset(max(self.node.now(), self.stream.time), self._load_kg)


class ArmSimulation:
    """The arm behind the simulator node: JointTrajectory commands in, ``/joint_states`` out.

    Args:
        node: The node (its clock, logger, endpoints).
        values: Its parameter values.

    Attributes:
        stream: The arm's prediction.
        accepted: Commands followed.
        refused: Commands refused.
        last_refusal: Why the last one was refused.
        joint_states_published: Messages published on ``/joint_states``.
        adopted: Identified arms adopted from ``/arm_params``.

    Raises:
        ConfigError: The arm or camera file is missing or malformed.
    """

    name = 'arm'

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
        # The beam rig's board hangs at a beam's tip: an arm draws one only when given.
        self._board = load_board(values['camera_config']) if values['camera_config'] else None
        self._latest: ArmMotion | None = None
        self._samples: ArmMotion | None = None  # the samples being published
        self._joints_out = publisher(node, JointState, JOINT_STATES)
        command_subscription(node, values['arm_commands'], self._on_command, self._refuse)
        self.config = config
        self.adopted = 0
        if values['adopt_identified']:
            subscription(node, DiagnosticArray, ARM_PARAMS, self._on_arm_params)
        self.description = (
            f'{config.n_joints}-link arm ({self.model.chain.n} segments) from '
            f'{values["arm_config"]}, following {values["arm_commands"]}'
        )

    # -- the model's side of the loop ---------------------------------------------------------

    def advance_to(self, now: float) -> TipSeries:
        """The samples due up to ``now`` (none before the first command)."""
        samples = self.stream.advance_to(now)
        self._samples = samples
        if samples.t.size:
            self._latest = samples
        return TipSeries(samples.t, samples.tip_x, samples.tip_z, samples.tip_pitch)

    def restart_at(self, now: float) -> bool:
        """Restarts at rest at the held angles (False: no command followed yet)."""
        if not self.stream.started:
            return False
        self.stream.restart_at(now)
        return True

    def published(self, stamp_ns: int, index: int) -> None:
        """Publishes the commanded angles of the sample just published."""
        assert self._samples is not None
        self._joints_out.publish(
            serialize(joint_state(stamp_ns, self.stream.joint_names, self._samples.q[index]))
        )
        self.joint_states_published += 1

    def latest_stamp(self) -> float | None:
        """The stamp of the last sample published (``None``: none yet)."""
        return None if self._latest is None else float(self._latest.t[-1])

    def scene(self, measured: TipPoint | None) -> BeamScene:
        """The arm's last published sample, drawn link by link."""
        latest = self._latest
        assert latest is not None
        return BeamScene(
            self._lengths,
            phi=latest.phi[-1],
            measured=measured,
            predicted=TipPoint(float(latest.tip_x[-1]), float(latest.tip_z[-1])),
            board=self._board,
            link_starts=self._link_starts,
        )

    def on_change(self, changes: Mapping[str, Any]) -> str | None:
        """The arm takes its parameters at start only."""
        return 'the arm mode takes its parameters at start only'

    # -- its input ----------------------------------------------------------------------------

    def _on_arm_params(self, msg: DiagnosticArray) -> None:
        """Adopts the identified arm: the next command (or ring-down extension) simulates it."""
        for status in msg.status:
            if status.name != ARM_STATUS:
                continue
            pairs = {kv.key: kv.value for kv in status.values}
            try:
                arm = arm_from_status(_level(status), pairs, self.config)
                model = ArmModel.from_config(arm)
            except LumpbeamError as exc:
                self.node.refuse(ARM_PARAMS, f'arm refused ({exc})', 'keeping the last one')
                continue
            self.model = self.stream.model = model
            self.adopted += 1
            self.node.get_logger().info(f'adopted the arm of {ARM_PARAMS} ({status.message})')

    def _on_command(self, msg: JointTrajectoryMsg) -> None:
        now = self.node.now()
        try:
            command = command_from_msg(msg)
            start = max(command.stamp_s, now) if command.stamp_s > 0.0 else now
            self.stream.command(command.joint_names, command.time_s, command.positions_rad, start)
        except LumpbeamError as exc:
            self._refuse(str(exc))
            return
        self.accepted += 1
        self.node.get_logger().info(
            f'following a command of {command.time_s.size} points from {start:.3f} s '
            f'({command.time_s[-1]:.3f} s long)'
        )

    def _refuse(self, reason: str) -> None:
        self.refused += 1
        self.last_refusal = reason
        self.node.refuse(
            self.values['arm_commands'], f'command refused ({reason})', 'keeping the motion'
        )


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
