"""The arm demos' live graph, and the demo's own node that commands the arm and plays its camera.

Both arm demos (``lumpbeam demo --arm`` and ``--workspace``) run the same graph as separate
processes on a private ROS domain, on wall time: two simulator nodes in arm mode following
``/joint_trajectory_shaped``, one as *the arm* (its tip on ``/tip_pose_truth``, its joint
angles on ``/real_arm/joint_states``) and one as *the model* (``/joint_states``,
``/tip_pose_predicted``, ``/beam_markers``), the identifier node, the shaper node and the
recorder. What differs is each node's parameters (:class:`ArmGraph`) and what the demo
commands (a function of an :class:`ArmDriver`).

The driver is the demo's node: it publishes each command stamped a little ahead, so that both
simulators (and the shaper in between) receive it before it starts and start it at the same
instant, and it is the arm's camera: the arm's tip republished on ``/tip_pose`` with the
synthetic camera's noise, at the same stamp.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import TracebackType
from typing import Any, Protocol

import numpy as np

from lumpbeam_ros.apps.demo.graph import ProcessGraph, node_command, python_command, wait_for_graph
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import (
    BEAM_MARKERS,
    IDENTIFIER_NODE,
    JOINT_STATE_TYPE,
    JOINT_STATES,
    JOINT_TRAJECTORY,
    JOINT_TRAJECTORY_SHAPED,
    JOINT_TRAJECTORY_TYPE,
    MARKER_ARRAY,
    POSE_STAMPED,
    RECORDER_NODE,
    SHAPER_NODE,
    SIMULATOR_NODE,
    TIP_POSE,
    TIP_POSE_PREDICTED,
    TIP_POSE_TRUTH,
)
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory, default_joint_names
from lumpbeam_ros.core.synthetic.arm_bag import ArmSynthOptions
from lumpbeam_ros.core.synthetic.drop_test import PITCH_NOISE_PER_M

SIMULATOR_MODULE = 'lumpbeam_ros.nodes.simulator_node'
IDENTIFIER_MODULE = 'lumpbeam_ros.nodes.identifier_node'
SHAPER_MODULE = 'lumpbeam_ros.nodes.shaper_node'
CLI_MODULE = 'lumpbeam_ros.apps.cli.main'
#: The simulator node playing the arm itself: its name, and its outputs kept out of the way
#: of the model's (only its tip is the graph's measurement).
REAL_ARM = 'real_arm'
#: The arm's own joint angles.
REAL_ARM_JOINT_STATES = f'/{REAL_ARM}{JOINT_STATES}'
#: What the recorder records in both demos, with the types the probe announces them with.
RECORDED_TOPICS = {
    JOINT_TRAJECTORY: JOINT_TRAJECTORY_TYPE,
    JOINT_TRAJECTORY_SHAPED: JOINT_TRAJECTORY_TYPE,
    JOINT_STATES: JOINT_STATE_TYPE,
    REAL_ARM_JOINT_STATES: JOINT_STATE_TYPE,
    TIP_POSE: POSE_STAMPED,
    TIP_POSE_TRUTH: POSE_STAMPED,
    TIP_POSE_PREDICTED: POSE_STAMPED,
    BEAM_MARKERS: MARKER_ARRAY,
}
#: The camera's noise on ``/tip_pose``: the synthetic bags' (``lumpbeam synth``), m ...
NOISE_M = ArmSynthOptions.noise_m
#: ... and its seed.
NOISE_SEED = 0
#: Subscribers of ``/joint_trajectory`` the driver waits for: the shaper and the recorder.
COMMAND_READERS = 2
#: Subscribers of ``/tip_pose`` it waits for: the identifier, the recorder, the model.
CAMERA_READERS = 3
#: The joints hold still this long at the start of each command, so the record shows the
#: arm at rest before it moves, s.
HOLD_S = 0.3
#: How long the children get to match each other's endpoints once the probe sees them all, s.
SETTLE_S = 2.0
#: Longest wait for the simulators to publish past a point in time, s (wall time: a busy
#: machine delays their ticks, not their samples' stamps).
RECORD_TIMEOUT_S = 60.0
#: Longest wait for a child's log line or the shaper's output, s.
ANSWER_TIMEOUT_S = 10.0


def minimum_jerk(start: np.ndarray, end: np.ndarray, duration_s: float) -> JointTrajectory:
    """A rest-to-rest minimum-jerk move at 1 kHz, after :data:`HOLD_S` at ``start``.

    Args:
        start: Angles it starts from, rad.
        end: Angles it ends at, rad.
        duration_s: The move's length, s.

    Returns:
        The command, times from its start.
    """
    t = np.linspace(0.0, duration_s, int(round(duration_s * 1000)) + 1)
    s = t / duration_s
    s = 10 * s**3 - 15 * s**4 + 6 * s**5
    angles = np.vstack([start, start + np.outer(s, end - start)])
    angles[-1] = end  # exactly, not to the rounding of start + (end - start)
    names = default_joint_names(start.size)
    return JointTrajectory(np.concatenate([[0.0], HOLD_S + t]), angles, names)


@dataclass(frozen=True)
class ArmGraph:
    """What the nodes of an arm demo's graph are given beyond their defaults.

    Attributes:
        real_arm: The arm file of the arm itself.
        model: The arm file the model, the identifier and the shaper are given.
        model_args: More ``--ros-args`` of the model's simulator node.
        identifier_args: ``--ros-args`` of the identifier node.
        shaper_args: ``--ros-args`` of the shaper node.
        recorded: Topics recorded (with their types) beyond :data:`RECORDED_TOPICS`.
        readers: Subscribers per topic the nodes add to the probe's and the recorder's.
    """

    real_arm: Path
    model: Path
    model_args: tuple[str, ...] = ()
    identifier_args: tuple[str, ...] = ()
    shaper_args: tuple[str, ...] = ()
    recorded: Mapping[str, str] = field(default_factory=dict)
    readers: Mapping[str, int] = field(default_factory=dict)

    @property
    def topics(self) -> dict[str, str]:
        """Every topic recorded, with its type."""
        return {**RECORDED_TOPICS, **self.recorded}

    def subscribers(self) -> dict[str, int]:
        """Subscribers each topic must have before the first command."""
        readers = dict.fromkeys(self.topics, 2)  # the probe's and the recorder's
        readers[JOINT_TRAJECTORY] += 1  # the shaper
        readers[JOINT_TRAJECTORY_SHAPED] += 2  # both simulators
        readers[TIP_POSE] += 2  # the identifier, the model's markers
        readers[JOINT_STATES] += 1  # the identifier
        for topic, count in self.readers.items():
            readers[topic] += count
        return readers


class ArmRunOptions(Protocol):
    """What an arm demo's options say about its graph."""

    @property
    def domain_id(self) -> int | None:
        """ROS domain; when ``None``, a free one."""

    @property
    def ready_timeout_s(self) -> float:
        """Longest wait for the nodes to join the graph, s."""


class ArmRun(Protocol):
    """What an arm demo's run gives its graph (``ArmDemoRun``, ``WorkspaceDemoRun``)."""

    options: ArmRunOptions
    recorded_bag: Path
    echo: Callable[[str], None]

    @property
    def log_dir(self) -> Path:
        """The children's logs."""


def run_arm_graph(spec: ArmGraph, run: ArmRun, drive: Callable[[ArmDriver], None]) -> None:
    """Starts the graph, lets ``drive`` command it, stops it and closes the recording.

    Args:
        spec: The nodes' parameters.
        run: The demo's run: its domain, logs, recording (``recorded_bag``) and echo.
        drive: What the demo commands, with a ready driver.

    Raises:
        LumpbeamError: The graph did not start, ``drive`` failed, or a child exited.
    """
    log_dir, bag, echo = run.log_dir, run.recorded_bag, run.echo
    domain_id, ready_timeout_s = run.options.domain_id, run.options.ready_timeout_s
    follow = ('-p', f'arm_commands:={JOINT_TRAJECTORY_SHAPED}')
    real_arm = (
        *follow,
        '-p',
        f'arm_config:={spec.real_arm}',
        '-p',
        'markers_rate_hz:=0.0',
        '-r',
        f'__node:={REAL_ARM}',
        '-r',
        f'{TIP_POSE_PREDICTED[1:]}:={TIP_POSE_TRUTH[1:]}',
        '-r',
        f'{JOINT_STATES[1:]}:={REAL_ARM_JOINT_STATES[1:]}',
        '-r',
        f'{BEAM_MARKERS[1:]}:={REAL_ARM}{BEAM_MARKERS}',
    )
    model = (*follow, '-p', f'arm_config:={spec.model}', *spec.model_args)
    with ProcessGraph(log_dir, domain_id) as graph:
        echo(f'  ROS_DOMAIN_ID={graph.domain_id}, logs in {log_dir} (wall time)')
        graph.start('simulator', node_command(SIMULATOR_MODULE, *model))
        graph.start(REAL_ARM, node_command(SIMULATOR_MODULE, *real_arm))
        graph.start('identifier', node_command(IDENTIFIER_MODULE, *spec.identifier_args))
        graph.start('shaper', node_command(SHAPER_MODULE, *spec.shaper_args))
        graph.start('recorder', python_command(CLI_MODULE, 'record', str(bag), *spec.topics))
        wait_for_graph(
            graph,
            [SIMULATOR_NODE, REAL_ARM, IDENTIFIER_NODE, SHAPER_NODE, RECORDER_NODE],
            spec.subscribers(),
            ready_timeout_s,
            announce=spec.topics,
        )
        with ArmDriver(graph, log_dir) as driver:
            driver.wait_ready(ready_timeout_s)
            drive(driver)
        for name in [name for name in graph.children if name != 'recorder']:
            try:
                graph.interrupt(name)
            except LumpbeamError as exc:
                echo(f'  warning: {exc}')  # the recording is complete
        graph.interrupt('recorder')  # must stop cleanly: it closes the bag
    echo(f'  recorded {bag}')


class ArmDriver:
    """The demo's node on the graph: it commands the arm, plays its camera and listens.

    Args:
        graph: The running graph (its domain; its children are checked while waiting).
        log_dir: The children's logs (named in errors, read by :meth:`wait_for_line`).

    Attributes:
        shaped: Every ``/joint_trajectory_shaped`` received, in order.
        tip_s: The latest stamp of the arm's tip, s.
    """

    def __init__(self, graph: ProcessGraph, log_dir: Path):
        self.graph = graph
        self.log_dir = log_dir
        self.shaped: list[JointTrajectory] = []
        self.tip_s = -math.inf
        self._rng = np.random.default_rng(NOISE_SEED)
        self._context: Any = None

    def __enter__(self) -> ArmDriver:
        import rclpy
        from geometry_msgs.msg import PoseStamped
        from rclpy.context import Context
        from rclpy.executors import SingleThreadedExecutor
        from rclpy.node import Node
        from trajectory_msgs.msg import JointTrajectory as JointTrajectoryMsg

        from lumpbeam_ros.nodes.msgtypes import topic_qos
        from lumpbeam_ros.nodes.trajectory_messages import trajectory_from_msg

        self._context = Context()
        rclpy.init(context=self._context, domain_id=self.graph.domain_id)
        self.node = Node('lumpbeam_demo_arm_driver', context=self._context)
        self._command = self.node.create_publisher(
            JointTrajectoryMsg, JOINT_TRAJECTORY, topic_qos(JOINT_TRAJECTORY)
        )
        self._camera = self.node.create_publisher(PoseStamped, TIP_POSE, topic_qos(TIP_POSE))
        self.listen(PoseStamped, TIP_POSE_TRUTH, self._on_tip)
        self.listen(
            JointTrajectoryMsg,
            JOINT_TRAJECTORY_SHAPED,
            lambda msg: self.shaped.append(trajectory_from_msg(msg)),
        )
        self._executor = SingleThreadedExecutor(context=self._context)
        self._executor.add_node(self.node)
        return self

    def __exit__(
        self,
        _type: type[BaseException] | None,
        _value: BaseException | None,
        _traceback: TracebackType | None,
    ) -> None:
        import rclpy

        try:
            self._executor.shutdown()
            self.node.destroy_node()
        finally:
            rclpy.try_shutdown(context=self._context)

    def listen(self, msg_type: Any, topic: str, callback: Callable[[Any], None]) -> None:
        """Subscribes to a topic with its QoS of the contract."""
        from lumpbeam_ros.nodes.msgtypes import topic_qos

        self.node.create_subscription(msg_type, topic, callback, topic_qos(topic))

    def _on_tip(self, msg: Any) -> None:
        # The camera: the arm's tip with the synthetic camera's noise, at the same stamp.
        from lumpbeam_ros.core.bagio.convert import pose_stamped, pose_values
        from lumpbeam_ros.core.bagio.typestore import serialize

        stamp_ns, x, z, pitch, frame = pose_values(msg)
        dx, dz, dpitch = NOISE_M * self._rng.standard_normal(3)
        noisy = pose_stamped(stamp_ns, x + dx, z + dz, pitch + dpitch * PITCH_NOISE_PER_M, frame)
        self._camera.publish(serialize(noisy))
        self.tip_s = max(self.tip_s, stamp_ns / 1e9)

    def spin_until(self, done: Callable[[], bool], timeout_s: float, what: str) -> None:
        """Spins until ``done()``.

        Raises:
            LumpbeamError: ``what`` (the failure) not done within ``timeout_s``, or a child
                exited.
        """
        deadline = time.monotonic() + timeout_s
        while not done():
            if time.monotonic() > deadline:
                raise LumpbeamError(f'{what} within {timeout_s:g} s (logs: {self.log_dir})')
            self.graph.check_running()
            self._executor.spin_once(timeout_sec=0.05)

    def wait_ready(self, timeout_s: float) -> None:
        """Waits until the nodes have discovered the demo's commands and camera, and settled.

        Discovery of a new publisher takes seconds on a busy machine: a command published
        before the shaper and the recorder have matched it would be lost.
        """
        self.spin_until(
            lambda: (
                self._command.get_subscription_count() >= COMMAND_READERS
                and self._camera.get_subscription_count() >= CAMERA_READERS
                and self.node.count_publishers(TIP_POSE_TRUTH) >= 1
                and self.node.count_publishers(JOINT_TRAJECTORY_SHAPED) >= 1
            ),
            timeout_s,
            'the nodes did not discover the demo (its commands and its camera)',
        )
        # The probe sees every endpoint, but not whether the children have matched each
        # other's: the shaper's forward of a move reached the arm and not the recorder once,
        # on a loaded machine. The children's own discovery gets a moment more.
        settled = time.monotonic() + SETTLE_S
        self.spin_until(lambda: time.monotonic() > settled, SETTLE_S + 1.0, 'settling')

    def publish(self, move: JointTrajectory, lead_s: float) -> float:
        """Publishes a command stamped ``lead_s`` ahead.

        Returns:
            Its stamp, s (wall time).
        """
        from trajectory_msgs.msg import JointTrajectory as JointTrajectoryMsg

        from lumpbeam_ros.nodes.trajectory_messages import trajectory_msg

        start_ns = self.node.get_clock().now().nanoseconds + int(lead_s * 1e9)
        like = JointTrajectoryMsg()
        like.header.stamp.sec, like.header.stamp.nanosec = divmod(start_ns, 10**9)
        self._command.publish(trajectory_msg(move, like))
        return start_ns / 1e9

    def wait_for_shaped(self, count: int, timeout_s: float = ANSWER_TIMEOUT_S) -> JointTrajectory:
        """Waits for the ``count``-th command on ``/joint_trajectory_shaped``; returns it."""
        self.spin_until(
            lambda: len(self.shaped) >= count, timeout_s, f'the shaper published no move {count}'
        )
        return self.shaped[count - 1]

    def wait_for_tip(self, stamp_s: float, what: str, timeout_s: float) -> None:
        """Waits until the arm's tip has been seen at ``stamp_s`` or later."""
        self.spin_until(lambda: self.tip_s >= stamp_s, timeout_s, what)

    def wait_for_line(self, name: str, text: str) -> str:
        """Waits until a child's log has a line with ``text``; returns its message part."""
        found: list[str] = []

        def has_line() -> bool:
            log = self.graph.children[name].log_path.read_text(encoding='utf-8', errors='replace')
            found[:] = [line for line in log.splitlines() if text in line]
            return bool(found)

        self.spin_until(has_line, ANSWER_TIMEOUT_S, f'the {name} node did not log {text!r}')
        line = found[-1]
        return line[line.index(text) :]
