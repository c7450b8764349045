"""``lumpbeam demo --arm FILE``: the input-shaping loop live on a simulated flexible arm.

An arm moves unshaped and rings; the identifier node identifies the modes of its ring-down;
the shaper node adopts them; the move back is shaped and rings far less. The steps:

1. ``loop``: the live graph as separate processes on a private ROS domain (wall time: no bag
   is replayed, so nothing publishes ``/clock``): two simulator nodes in arm mode following
   ``/joint_trajectory_shaped``, one as *the arm* (its tip on ``/tip_pose``, the
   measurement, its joint angles on ``/real_arm/joint_states``) and one as *the model*
   (``/joint_states``, ``/tip_pose_predicted``, ``/beam_markers``), the identifier node, the
   shaper node (``source: beam_params``, forwarding unshaped until its first estimate) and
   the recorder. This process publishes move 1 (out) on ``/joint_trajectory``, waits until
   an OK estimate is on ``/beam_params`` and the shaper has adopted it, publishes move 2
   (back), which the shaper shapes, and stops the graph once the ring-down after move 2 is
   recorded. Each command is stamped a little ahead, so both simulators start it at the same
   instant.
2. ``residuals``: each move's residual vibration from the recorded ``/joint_states`` and
   ``/tip_pose`` (:func:`~lumpbeam_ros.core.shaping.loop.bag_move_residuals`).
3. ``figure`` and ``summary``: both residuals drawn, printed and written to ``summary.json``;
   the step fails (one line) when the shaped move rings less than 90 % less.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from lumpbeam_ros.apps.demo.graph import ProcessGraph, node_command, python_command, wait_for_graph
from lumpbeam_ros.apps.demo.run import BAGS_DIR, DemoFolders, fresh_bags_dir, run_steps
from lumpbeam_ros.apps.json_output import typed_values, write_json
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import (
    BEAM_MARKERS,
    BEAM_PARAMS,
    DIAGNOSTIC_ARRAY,
    IDENTIFIER_NODE,
    IDENTIFIER_STATUS,
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
from lumpbeam_ros.core.model.arm.config import ArmConfig, load_arm_config
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory, default_joint_names
from lumpbeam_ros.core.model.arm.residual import WINDOW_S
from lumpbeam_ros.core.shaping.loop import ShapingOutcome, bag_move_residuals
from lumpbeam_ros.core.synthetic.arm_bag import ArmSynthOptions
from lumpbeam_ros.core.synthetic.drop_test import PITCH_NOISE_PER_M

SIMULATOR_MODULE = 'lumpbeam_ros.nodes.simulator_node'
IDENTIFIER_MODULE = 'lumpbeam_ros.nodes.identifier_node'
SHAPER_MODULE = 'lumpbeam_ros.nodes.shaper_node'
CLI_MODULE = 'lumpbeam_ros.apps.cli.main'
#: The simulator node playing the arm itself: its name, and its outputs kept out of the way
#: of the model's (only its tip is the graph's measurement).
REAL_ARM = 'real_arm'
#: What the recorder records, with the types the probe announces them with.
RECORDED_TOPICS = {
    JOINT_TRAJECTORY: JOINT_TRAJECTORY_TYPE,
    JOINT_TRAJECTORY_SHAPED: JOINT_TRAJECTORY_TYPE,
    JOINT_STATES: JOINT_STATE_TYPE,
    TIP_POSE: POSE_STAMPED,
    TIP_POSE_TRUTH: POSE_STAMPED,
    TIP_POSE_PREDICTED: POSE_STAMPED,
    BEAM_PARAMS: DIAGNOSTIC_ARRAY,
    BEAM_MARKERS: MARKER_ARRAY,
}
#: The camera's noise on ``/tip_pose``: the synthetic bags' (``lumpbeam synth``), m ...
NOISE_M = ArmSynthOptions.noise_m
#: ... and its seed.
NOISE_SEED = 0
#: What the shaper node logs when it adopts an estimate.
SHAPER_ADOPTED = 'shaping with'
#: Subscribers of ``/joint_trajectory`` the driver waits for: the shaper and the recorder.
COMMAND_READERS = 2
#: Subscribers of ``/tip_pose`` it waits for: the identifier, the recorder, the model.
CAMERA_READERS = 3
#: Each move turns joint 1 by this much (the other joints stay at 0), rad ...
MOVE_RAD = 1.0
#: ... in this long (a minimum-jerk profile sampled at 1 kHz), s.
MOVE_S = 0.3
#: The joints hold still this long at the start of each command, so the record shows the
#: arm at rest before it moves, s.
HOLD_S = 0.3
#: Commands are stamped this far ahead of their publication: both simulators (and the
#: shaper in between) receive them before they start, and start them at the same instant, s.
LEAD_S = 1.0
#: Recorded past each residual window, s.
MARGIN_S = 0.5
#: Move 2 waits until move 1's vibration has decayed to this fraction of its amplitude.
LEFT_RINGING = 0.02
#: ... but at most this long, s (a lightly damped arm would keep the demo waiting minutes).
MAX_GAP_S = 30.0
#: How long the children get to match each other's endpoints once the probe sees them all, s.
SETTLE_S = 2.0
#: Longest wait for the identifier's OK estimate and the shaper's adoption after move 1, s.
ESTIMATE_TIMEOUT_S = 60.0
#: Longest wait for the simulators to publish past a residual window, s (wall time: a busy
#: machine delays their ticks, not their samples' stamps).
RECORD_TIMEOUT_S = 60.0
#: The shaped move must ring at least this much less than the unshaped one.
MIN_REDUCTION = 0.90
#: Every mode a status may hold (the identifier's most).
ALL_MODES = 8
#: The figure's file under ``out/figures``.
FIGURE_NAME = 'shaping_before_after.png'


@dataclass(frozen=True)
class ArmDemoOptions:
    """What ``lumpbeam demo --arm`` varies.

    Attributes:
        arm_config: The arm file (doc/arm.md).
        out: Output folder (bags, logs, figure, summary).
        domain_id: ROS domain; when ``None``, one no other lumpbeam process holds.
        ready_timeout_s: Longest wait for the nodes to join the graph, s.
    """

    arm_config: Path
    out: Path = Path('results')
    domain_id: int | None = None
    ready_timeout_s: float = 60.0


@dataclass
class ArmDemoRun(DemoFolders):
    """The state the steps share and fill in.

    Attributes:
        options: The options.
        arm: The arm.
        echo: Where progress lines go.
        recorded_bag: What the recorder wrote.
        estimate: The OK ``/beam_params`` values the shaper adopted before move 2.
        shaper_log: The shaper node's line saying what it shapes with.
        added_s: How much longer the shaper made move 2, s.
        outcome: Both moves' residuals.
        figure: The before/after figure.
        summary: The machine-readable summary (also ``summary.json``).
        step_seconds: Wall time of each step, s.
    """

    options: ArmDemoOptions
    arm: ArmConfig
    echo: Callable[[str], None] = print
    recorded_bag: Path = Path()
    estimate: dict[str, str] = field(default_factory=dict)
    shaper_log: str = ''
    added_s: float = math.nan
    outcome: ShapingOutcome | None = None
    figure: Path = Path()
    summary: dict[str, Any] = field(default_factory=dict)
    step_seconds: dict[str, float] = field(default_factory=dict)


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
    names = default_joint_names(start.size)
    return JointTrajectory(np.concatenate([[0.0], HOLD_S + t]), angles, names)


def the_moves(arm: ArmConfig) -> tuple[JointTrajectory, JointTrajectory]:
    """Move 1 (joint 1 out by :data:`MOVE_RAD`) and move 2 (back to where it started)."""
    near = np.zeros(arm.n_joints)
    far = near.copy()
    far[0] = MOVE_RAD
    return minimum_jerk(near, far, MOVE_S), minimum_jerk(far, near, MOVE_S)


def loop(run: ArmDemoRun) -> None:
    """Runs the live graph through both moves and records it (``out/bags/recorded``)."""
    bags = fresh_bags_dir(run.out / BAGS_DIR)
    run.recorded_bag = bags / 'recorded'
    arm = str(run.options.arm_config)
    follow = ('-p', f'arm_config:={arm}', '-p', f'arm_commands:={JOINT_TRAJECTORY_SHAPED}')
    real_arm = (
        *follow,
        '-p',
        'markers_rate_hz:=0.0',
        '-r',
        f'__node:={REAL_ARM}',
        '-r',
        f'{TIP_POSE_PREDICTED[1:]}:={TIP_POSE_TRUTH[1:]}',
        '-r',
        f'{JOINT_STATES[1:]}:={REAL_ARM}{JOINT_STATES}',
        '-r',
        f'{BEAM_MARKERS[1:]}:={REAL_ARM}{BEAM_MARKERS}',
    )
    shaper = ('-p', 'source:=beam_params', '-p', 'unshaped_until_estimate:=true')
    # Readers each topic must have before move 1: the probe's and the recorder's, plus the
    # nodes' own inputs.
    readers = dict.fromkeys(RECORDED_TOPICS, 2)
    readers[JOINT_TRAJECTORY] += 1  # the shaper
    readers[JOINT_TRAJECTORY_SHAPED] += 2  # both simulators
    readers[BEAM_PARAMS] += 1  # the shaper
    readers[TIP_POSE] += 2  # the identifier, the model's markers
    readers[JOINT_STATES] += 1  # the identifier
    with ProcessGraph(run.log_dir, run.options.domain_id) as graph:
        run.echo(f'  ROS_DOMAIN_ID={graph.domain_id}, logs in {run.log_dir} (wall time)')
        graph.start('simulator', node_command(SIMULATOR_MODULE, *follow))
        graph.start(REAL_ARM, node_command(SIMULATOR_MODULE, *real_arm))
        graph.start('identifier', node_command(IDENTIFIER_MODULE))
        graph.start('shaper', node_command(SHAPER_MODULE, *shaper))
        graph.start(
            'recorder',
            python_command(CLI_MODULE, 'record', str(run.recorded_bag), *RECORDED_TOPICS),
        )
        wait_for_graph(
            graph,
            [SIMULATOR_NODE, REAL_ARM, IDENTIFIER_NODE, SHAPER_NODE, RECORDER_NODE],
            readers,
            run.options.ready_timeout_s,
            announce=RECORDED_TOPICS,
        )
        _drive(graph, run)
        names = [name for name in graph.children if name != 'recorder']
        for name in names:
            try:
                graph.interrupt(name)
            except LumpbeamError as exc:
                run.echo(f'  warning: {exc}')  # the recording is complete
        graph.interrupt('recorder')  # must stop cleanly: it closes the bag
    run.echo(f'  recorded {run.recorded_bag}')


def _drive(graph: ProcessGraph, run: ArmDemoRun) -> None:
    """Publishes the two moves, waiting for the estimate between them and the ring-down after.

    Raises:
        LumpbeamError: No OK estimate or no adoption in time, move 2 not shaped, the
            simulators not publishing, or a child exited.
    """
    import rclpy
    from diagnostic_msgs.msg import DiagnosticArray
    from geometry_msgs.msg import PoseStamped
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node
    from trajectory_msgs.msg import JointTrajectory as JointTrajectoryMsg

    from lumpbeam_ros.core.bagio.convert import pose_stamped, pose_values
    from lumpbeam_ros.core.bagio.typestore import serialize
    from lumpbeam_ros.core.shaping.estimate import estimate_from_status
    from lumpbeam_ros.nodes.msgtypes import topic_qos
    from lumpbeam_ros.nodes.trajectory_messages import trajectory_from_msg, trajectory_msg

    move_out, move_back = the_moves(run.arm)
    seen: dict[str, Any] = {'tip_s': -math.inf, 'ok': None, 'shaped': []}

    def on_params(msg: DiagnosticArray) -> None:
        for status in msg.status:
            if status.name != IDENTIFIER_STATUS or status.level[0] != 0:
                continue
            values = {kv.key: kv.value for kv in status.values}
            try:
                estimate_from_status(0, values, ALL_MODES)
            except LumpbeamError:
                continue  # the shaper refuses it too
            seen['ok'] = values

    rng = np.random.default_rng(NOISE_SEED)

    def on_tip(msg: PoseStamped) -> None:
        # The camera: the arm's tip with the synthetic camera's noise, at the same stamp.
        stamp_ns, x, z, pitch, frame = pose_values(msg)
        dx, dz, dpitch = NOISE_M * rng.standard_normal(3)
        camera.publish(
            serialize(
                pose_stamped(stamp_ns, x + dx, z + dz, pitch + dpitch * PITCH_NOISE_PER_M, frame)
            )
        )
        seen['tip_s'] = max(seen['tip_s'], stamp_ns / 1e9)

    def on_shaped(msg: JointTrajectoryMsg) -> None:
        seen['shaped'].append(trajectory_from_msg(msg))

    context = Context()
    rclpy.init(context=context, domain_id=graph.domain_id)
    try:
        node = Node('lumpbeam_demo_arm_driver', context=context)
        command = node.create_publisher(
            JointTrajectoryMsg, JOINT_TRAJECTORY, topic_qos(JOINT_TRAJECTORY)
        )
        node.create_subscription(DiagnosticArray, BEAM_PARAMS, on_params, 10)
        camera = node.create_publisher(PoseStamped, TIP_POSE, topic_qos(TIP_POSE))
        node.create_subscription(PoseStamped, TIP_POSE_TRUTH, on_tip, topic_qos(TIP_POSE_TRUTH))
        node.create_subscription(
            JointTrajectoryMsg, JOINT_TRAJECTORY_SHAPED, on_shaped, topic_qos(JOINT_TRAJECTORY)
        )
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(node)

        def spin_until(done: Callable[[], bool], timeout_s: float, what: str) -> None:
            deadline = time.monotonic() + timeout_s
            while not done():
                if time.monotonic() > deadline:
                    raise LumpbeamError(f'{what} within {timeout_s:g} s (logs: {run.log_dir})')
                graph.check_running()
                executor.spin_once(timeout_sec=0.05)

        def publish(move: JointTrajectory) -> float:
            """Publishes a move stamped LEAD_S ahead; returns its stamp, s (wall time)."""
            start_ns = node.get_clock().now().nanoseconds + int(LEAD_S * 1e9)
            like = JointTrajectoryMsg()
            like.header.stamp.sec, like.header.stamp.nanosec = divmod(start_ns, 10**9)
            command.publish(trajectory_msg(move, like))
            return start_ns / 1e9

        # Discovery of a new publisher takes seconds on a busy machine: a command published
        # before the shaper and the recorder have matched it would be lost.
        spin_until(
            lambda: (
                command.get_subscription_count() >= COMMAND_READERS
                and camera.get_subscription_count() >= CAMERA_READERS
                and node.count_publishers(TIP_POSE_TRUTH) >= 1
                and node.count_publishers(JOINT_TRAJECTORY_SHAPED) >= 1
            ),
            run.options.ready_timeout_s,
            'the nodes did not discover the demo (its commands and its camera)',
        )
        # The probe sees every endpoint, but not whether the children have matched each
        # other's: the shaper's forward of move 1 reached the arm and not the recorder once,
        # on a loaded machine. The children's own discovery gets a moment more.
        settled = time.monotonic() + SETTLE_S
        spin_until(lambda: time.monotonic() > settled, SETTLE_S + 1.0, 'settling')
        # Move 1: the shaper has no estimate yet and forwards it unshaped.
        start = publish(move_out)
        end_1 = start + float(move_out.time_s[-1])
        run.echo(f'  move 1: joint 1 to {MOVE_RAD:g} rad in {MOVE_S:g} s, unshaped')
        spin_until(lambda: len(seen['shaped']) >= 1, 10.0, 'the shaper forwarded no move 1')
        # The identifier's estimate of the ring-down, then the shaper's adoption of it, and
        # the whole residual window after move 1 before move 2 starts.
        seen['ok'] = None
        spin_until(
            lambda: seen['ok'] is not None,
            ESTIMATE_TIMEOUT_S,
            'no OK estimate of the ring-down on /beam_params',
        )
        _wait_for_line(graph, 'shaper', SHAPER_ADOPTED, spin_until)
        run.echo(
            f'  identified after {_age(seen, end_1):.1f} s of ring-down: the shaper adopts it'
        )
        # What move 1 leaves ringing adds to move 2's residual (the arm inherits it): wait
        # until the identified modes have decayed enough that it cannot count.
        settle = settle_time(seen['ok'])
        gap = min(max(WINDOW_S + MARGIN_S, settle), MAX_GAP_S)
        run.echo(f'  move 2 starts {gap:.1f} s after move 1 ends (the ring-down below 2 %)')
        if settle > gap:
            left = LEFT_RINGING ** (gap / settle)
            run.echo(
                f'  warning: the ring-down takes {settle:.0f} s to fall below 2 %; after '
                f'{gap:g} s, {100 * left:.0f} % of it is left and counts against move 2'
            )
        spin_until(
            lambda: seen['tip_s'] >= end_1 + gap - LEAD_S,
            gap + RECORD_TIMEOUT_S,
            'the arm did not ring down after move 1',
        )
        # Move 2: shaped with the latest estimate, which the shaper has adopted by now.
        run.estimate = dict(seen['ok'])
        start = publish(move_back)
        spin_until(lambda: len(seen['shaped']) >= 2, 10.0, 'the shaper published no move 2')
        run.shaper_log = _wait_for_line(graph, 'shaper', SHAPER_ADOPTED, spin_until)
        run.echo(f'  identified: {_modes_text(run.estimate)}')
        run.echo(f'  shaper node: {run.shaper_log}')
        shaped: JointTrajectory = seen['shaped'][1]
        run.added_s = float(shaped.time_s[-1] - move_back.time_s[-1])
        if run.added_s <= 0.0:
            raise LumpbeamError('the shaper published move 2 unshaped')
        run.echo(f'  move 2: back to 0 rad, shaped ({run.added_s:.3f} s added)')
        end_2 = start + float(shaped.time_s[-1])
        spin_until(
            lambda: seen['tip_s'] >= end_2 + WINDOW_S + MARGIN_S,
            RECORD_TIMEOUT_S,
            'the arm did not ring down after move 2',
        )
        executor.shutdown()
        node.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)


def _wait_for_line(
    graph: ProcessGraph,
    name: str,
    text: str,
    spin_until: Callable[[Callable[[], bool], float, str], None],
) -> str:
    """Waits until a child's log has a line with ``text``; returns its message part."""
    found: list[str] = []

    def has_line() -> bool:
        log = graph.children[name].log_path.read_text(encoding='utf-8', errors='replace')
        found[:] = [line for line in log.splitlines() if text in line]
        return bool(found)

    spin_until(has_line, 10.0, f'the {name} node did not log {text!r}')
    line = found[-1]
    return line[line.index(text) :]


def settle_time(values: dict[str, str]) -> float:
    """How long the identified modes take to decay to :data:`LEFT_RINGING` of their amplitude.

    Each mode's envelope decays as ``exp(-zeta omega_n t)``; the slowest one sets it.

    Args:
        values: An OK ``/beam_params`` status's values.

    Returns:
        The time, s.

    Raises:
        LumpbeamError: The status holds no valid estimate, or an undamped mode.
    """
    from lumpbeam_ros.core.shaping.estimate import estimate_from_status

    modes = estimate_from_status(0, values, ALL_MODES).modes
    rate = min(m.mode.damping_ratio * 2.0 * math.pi * m.mode.frequency_hz for m in modes)
    if rate <= 0.0:
        raise LumpbeamError('an identified mode is undamped: it would never ring down')
    return math.log(1.0 / LEFT_RINGING) / rate


def _age(seen: dict[str, Any], end_s: float) -> float:
    """How far the arm's tip has come past ``end_s``, s."""
    return float(seen['tip_s'] - end_s)


def _modes_text(values: dict[str, str]) -> str:
    """The modes of a ``/beam_params`` status, e.g. ``4.2058 +- 0.0002 Hz (zeta 0.0197)``."""
    from lumpbeam_ros.core.shaping.estimate import estimate_from_status

    estimate = estimate_from_status(0, values, ALL_MODES)
    return ', '.join(
        f'{m.mode.frequency_hz:.4f} +- {m.frequency_std_hz:.2g} Hz '
        f'(zeta {m.mode.damping_ratio:.4f} +- {m.damping_std:.2g})'
        for m in estimate.modes
    )


def residuals(run: ArmDemoRun) -> None:
    """Both moves' residual vibration from the recorded ``/joint_states`` and ``/tip_pose``."""
    moves = bag_move_residuals(run.recorded_bag, run.arm, TIP_POSE_TRUTH)
    if len(moves) != 2:
        raise LumpbeamError(f'{run.recorded_bag}: {len(moves)} move(s) recorded, expected 2')
    run.outcome = ShapingOutcome(moves[0], moves[1])


def figure(run: ArmDemoRun) -> None:
    """Draws the tip's distance from rest after each move (``figures/`` + :data:`FIGURE_NAME`)."""
    from lumpbeam_ros.apps.plots.shaping import plot_shaping_outcome

    run.figure = plot_shaping_outcome(_outcome(run), run.out / 'figures' / FIGURE_NAME)
    run.echo(f'  wrote {run.figure}')


def summarize(run: ArmDemoRun) -> None:
    """Prints both residuals and the reduction, writes ``summary.json``; fails under 90 %.

    Raises:
        LumpbeamError: The shaped move rang less than 90 % less than the unshaped one.
    """
    outcome = _outcome(run)
    run.summary = {
        'arm_config': str(run.options.arm_config),
        'identified': typed_values(run.estimate),
        'shaper': run.shaper_log,
        'shaped_duration_added_s': run.added_s,
        'residual_unshaped_m': outcome.unshaped.residual_m,
        'residual_shaped_m': outcome.shaped.residual_m,
        'reduction': outcome.reduction,
        'figure': str(run.figure),
        'recorded_bag': str(run.recorded_bag),
        'step_seconds': dict(run.step_seconds),
    }
    write_json(run.out / 'summary.json', run.summary)
    run.echo(outcome.summary())
    if outcome.reduction < MIN_REDUCTION:
        raise LumpbeamError(
            f'the shaped move rang {100 * outcome.reduction:.1f} % less than the unshaped one, '
            f'under the {100 * MIN_REDUCTION:.0f} % expected (see {run.figure})'
        )


ArmStep = tuple[str, Callable[[ArmDemoRun], None]]


def arm_steps() -> list[ArmStep]:
    """The arm demo's steps, in order."""
    return [('loop', loop), ('residuals', residuals), ('figure', figure), ('summary', summarize)]


def run_arm_demo(options: ArmDemoOptions, echo: Callable[[str], None] = print) -> ArmDemoRun:
    """Runs the arm demo's steps in order.

    Args:
        options: The arm file, output folder, domain.
        echo: Where progress and the summary go.

    Returns:
        The filled-in run.

    Raises:
        ConfigError: The arm file is missing or malformed.
        LumpbeamError: A step failed (its child processes are stopped first), or the
            shaped move rang less than 90 % less.
    """
    run = ArmDemoRun(options=options, arm=load_arm_config(options.arm_config), echo=echo)
    run_steps(run, arm_steps(), run.step_seconds, echo)
    return run


def _outcome(run: ArmDemoRun) -> ShapingOutcome:
    if run.outcome is None:
        raise LumpbeamError('the residuals step must run before this one')
    return run.outcome
