"""``lumpbeam demo --workspace``: the arm learned live, and every later move shaped by it.

The arm itself is not the arm file the nodes are given: each link's stiffness and damping
are 20 % off (:data:`REAL_FACTORS`). The arm visits five configurations; until the
identifier has learned the links from the ring-downs, the shaper forwards each move
unshaped and it rings; from then on each move, to a configuration never visited, is shaped
for the learned model's modes at its end and tuned on the model's simulation of it. The
steps:

1. ``loop``: the arm demos' live graph (:mod:`~lumpbeam_ros.apps.demo.arm_graph`): the
   identifier node given the arm file (it fits the links after each ring-down and publishes
   them on ``/arm_params``), the shaper node with ``source: model``, ``tune: true`` and
   ``unshaped_until_estimate: true``, the model's simulator adopting ``/arm_params``. This
   process publishes the five moves on ``/joint_trajectory``, each once the previous one's
   ring-down has decayed, and records everything, ``/arm_params`` included.
2. ``residuals``: each move's residual vibration from the recorded arm (its joint angles and
   its tip), beside two references simulated on the same arm: the move unshaped, and the
   move shaped and tuned by the arm file's model (what the nodes would have done without
   learning).
3. ``figure`` and ``summary``: the residuals drawn, printed and written to ``summary.json``;
   the step fails (one line) when the arm was never learned, or a move shaped by the learned
   model rings less than 90 % less than unshaped.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from lumpbeam_ros.apps.demo.arm_graph import (
    REAL_ARM_JOINT_STATES,
    RECORD_TIMEOUT_S,
    ArmDriver,
    ArmGraph,
    minimum_jerk,
    run_arm_graph,
)
from lumpbeam_ros.apps.demo.run import BAGS_DIR, DemoFolders, fresh_bags_dir, run_steps
from lumpbeam_ros.apps.json_output import typed_values, write_json
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import (
    ARM_PARAMS,
    ARM_STATUS,
    BEAM_PARAMS,
    DIAGNOSTIC_ARRAY,
    TIP_POSE_TRUTH,
)
from lumpbeam_ros.core.ident.arm.learner import RING_DOWNS_KEY, arm_from_status
from lumpbeam_ros.core.ident.arm.link_fit import link_stiffness_total, scaled_arm
from lumpbeam_ros.core.model.arm.config import ArmConfig, load_arm_config, write_arm_config
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.residual import WINDOW_S
from lumpbeam_ros.core.shaping.apply import shape_trajectory
from lumpbeam_ros.core.shaping.choices import DEFAULT_MAX_MODES
from lumpbeam_ros.core.shaping.loop import MoveResidual, bag_move_residuals
from lumpbeam_ros.core.shaping.workspace import WorkspaceShaper, model_modes, predicted_residual

#: Each link's stiffness factor of the arm itself against the file; its damping is the
#: file's divided by it (a softer link of the same material damps more per unit stiffness).
REAL_FACTORS = (0.8, 1.2)
#: The moves: the configuration each ends at (rad, per joint) and its length (s). The first
#: starts from all joints at 0; every configuration is visited once.
MOVES = (
    ((0.3, -0.4), 0.6),
    ((0.8, 1.2), 0.6),
    ((-0.5, 2.0), 0.7),
    ((1.0, -1.5), 0.8),
    ((0.0, 0.6), 0.5),
)
#: The shaper the shaper node designs before tuning.
SHAPER = 'zvd'
#: Commands are stamped this far ahead of their publication: the shaper tunes each move (a
#: fraction of a second of CPU) before both simulators start it, s.
LEAD_S = 3.0
#: Longest wait for the shaper's output of a move, s.
SHAPE_TIMEOUT_S = LEAD_S + 20.0
#: The next move waits until the slowest mode of the file's model at the configuration
#: reached has decayed to this fraction of its amplitude ...
LEFT_RINGING = 0.02
#: ... but at least the residual window and a margin, and at most this long, s.
MIN_GAP_S = WINDOW_S + 0.5
MAX_GAP_S = 30.0
#: The most a move forwarded unshaped can come out longer, s.
FORWARDED_S = 1e-6
#: Each move shaped by the learned model must ring at least this much less than unshaped.
MIN_REDUCTION = 0.90
#: The figure's file under ``out/figures``.
FIGURE_NAME = 'workspace_shaping.png'


@dataclass(frozen=True)
class WorkspaceDemoOptions:
    """What ``lumpbeam demo --workspace`` varies.

    Attributes:
        arm_config: The arm file the nodes are given (doc/arm.md).
        out: Output folder (bags, logs, the arm itself, figure, summary).
        domain_id: ROS domain; when ``None``, one no other lumpbeam process holds.
        ready_timeout_s: Longest wait for the nodes to join the graph, s.
    """

    arm_config: Path
    out: Path = Path('results')
    domain_id: int | None = None
    ready_timeout_s: float = 60.0


@dataclass(frozen=True)
class CommandedMove:
    """One move as commanded and as the shaper sent it on.

    Attributes:
        command: The move published on ``/joint_trajectory``.
        added_s: How much longer the shaper made it, s (0: forwarded unshaped).
        learned_from: Ring-downs of the latest OK ``/arm_params`` when it was published
            (``None`` before any).
    """

    command: JointTrajectory
    added_s: float
    learned_from: int | None

    @property
    def label(self) -> str:
        """``(0.3, -0.4) -> (0.8, 1.2) in 0.6 s``."""
        angles = self.command.angles_rad
        start, end = (', '.join(f'{a:g}' for a in q) for q in (angles[0], angles[-1]))
        duration = float(self.command.time_s[-1] - self.command.time_s[1])
        return f'({start}) -> ({end}) in {duration:g} s'

    @property
    def shaped(self) -> bool:
        """Whether the shaper shaped it (a forward differs by the stamps' nanoseconds)."""
        return self.added_s > FORWARDED_S

    @property
    def shaped_by(self) -> str:
        """Who shaped it, for the table."""
        if not self.shaped:
            return 'unshaped'
        if self.learned_from is None:
            return 'shaped'
        return f'learned ({self.learned_from} ring-down{"s" if self.learned_from > 1 else ""})'


@dataclass(frozen=True)
class MoveOutcome:
    """One move's residual vibration on the arm, against the references.

    Attributes:
        number: 1-based.
        commanded: The move.
        measured: Its residual from the record.
        unshaped_m: The arm's simulated residual after the move unshaped, m.
        file_model_m: The same after the move shaped and tuned by the arm file's model, m.
    """

    number: int
    commanded: CommandedMove
    measured: MoveResidual
    unshaped_m: float
    file_model_m: float

    @property
    def shaped_by(self) -> str:
        """Who shaped it."""
        return self.commanded.shaped_by

    @property
    def reduction(self) -> float:
        """``1 - measured / unshaped``: the fraction of the residual vibration removed."""
        return 1.0 - self.measured.residual_m / self.unshaped_m

    def as_json(self) -> dict[str, Any]:
        """The entry of ``moves`` in ``summary.json``."""
        return {
            'final_q': self.commanded.command.angles_rad[-1].tolist(),
            'shaped_by': self.commanded.shaped_by,
            'duration_added_s': self.commanded.added_s,
            'residual_m': self.measured.residual_m,
            'residual_unshaped_m': self.unshaped_m,
            'residual_file_model_m': self.file_model_m,
            'reduction': self.reduction,
        }


@dataclass
class WorkspaceDemoRun(DemoFolders):
    """The state the steps share and fill in.

    Attributes:
        options: The options.
        nominal: The arm file's arm.
        real: The arm itself.
        real_file: Where the arm itself is written (the arm simulator's file).
        echo: Where progress lines go.
        recorded_bag: What the recorder wrote.
        commanded: The moves as published, in order.
        arm_status: The latest OK ``/arm_params`` values.
        outcomes: Each move's residuals.
        figure: The figure.
        summary: The machine-readable summary (also ``summary.json``).
        step_seconds: Wall time of each step, s.
    """

    options: WorkspaceDemoOptions
    nominal: ArmConfig
    real: ArmConfig
    echo: Callable[[str], None] = print
    recorded_bag: Path = Path()
    commanded: list[CommandedMove] = field(default_factory=list)
    arm_status: dict[str, str] = field(default_factory=dict)
    outcomes: list[MoveOutcome] = field(default_factory=list)
    figure: Path = Path()
    summary: dict[str, Any] = field(default_factory=dict)
    step_seconds: dict[str, float] = field(default_factory=dict)

    @property
    def real_file(self) -> Path:
        """The arm itself, as an arm file."""
        return self.out / 'real_arm.yaml'


def real_arm(nominal: ArmConfig) -> ArmConfig:
    """The arm itself: each link's stiffness times :data:`REAL_FACTORS`, its damping over it.

    Raises:
        LumpbeamError: An arm with another number of links than the factors.
    """
    if nominal.n_joints != len(REAL_FACTORS):
        raise LumpbeamError(
            f'the workspace demo moves a {len(REAL_FACTORS)}-link arm; '
            f'{nominal.source or "the arm file"} has {nominal.n_joints}'
        )
    factors = np.asarray(REAL_FACTORS)
    beta = np.array([link.damping_beta for link in nominal.links]) / factors
    return scaled_arm(nominal, factors, beta)


def workspace_moves() -> list[JointTrajectory]:
    """The five moves, each from where the previous one ended."""
    moves = []
    start = np.zeros(len(MOVES[0][0]))
    for target, duration in MOVES:
        end = np.asarray(target, dtype=float)
        moves.append(minimum_jerk(start, end, duration))
        start = end
    return moves


def settle_gap(model: ArmModel, q: np.ndarray) -> float:
    """How long after a move the next one waits: the model's slowest decay to 2 %, bounded.

    Each mode's envelope decays as ``exp(-zeta omega_n t)``; the slowest one sets it.
    """
    modes = model_modes(model, q, DEFAULT_MAX_MODES, 'the settle time')
    rate = min(m.damping_ratio * 2.0 * math.pi * m.frequency_hz for m in modes)
    settle = math.log(1.0 / LEFT_RINGING) / rate if rate > 0.0 else math.inf
    return min(max(MIN_GAP_S, settle), MAX_GAP_S)


def loop(run: WorkspaceDemoRun) -> None:
    """Runs the live graph through the five moves and records it (``out/bags/recorded``)."""
    run.recorded_bag = fresh_bags_dir(run.out / BAGS_DIR) / 'recorded'
    write_arm_config(run.real_file, run.real)
    arm = run.options.arm_config
    spec = ArmGraph(
        real_arm=run.real_file,
        model=arm,
        model_args=('-p', 'adopt_identified:=true'),
        identifier_args=('-p', f'arm_config:={arm}'),
        shaper_args=(
            *('-p', 'source:=model', '-p', f'arm_config:={arm}', '-p', f'shaper:={SHAPER}'),
            *('-p', 'tune:=true', '-p', 'unshaped_until_estimate:=true'),
        ),
        recorded={ARM_PARAMS: DIAGNOSTIC_ARRAY, BEAM_PARAMS: DIAGNOSTIC_ARRAY},
        readers={ARM_PARAMS: 2},  # the shaper, the model
    )
    run_arm_graph(spec, run, lambda driver: _drive(driver, run))


def _drive(driver: ArmDriver, run: WorkspaceDemoRun) -> None:
    """Publishes each move once the previous one has rung down; notes how it was shaped.

    Raises:
        LumpbeamError: A move not forwarded in time, the simulators not publishing, or a
            child exited.
    """
    from diagnostic_msgs.msg import DiagnosticArray

    def on_arm(msg: DiagnosticArray) -> None:
        for status in msg.status:
            if status.name == ARM_STATUS and status.level[0] == 0:
                run.arm_status = {kv.key: kv.value for kv in status.values}

    driver.listen(DiagnosticArray, ARM_PARAMS, on_arm)
    model = ArmModel.from_config(run.nominal)
    for number, command in enumerate(workspace_moves(), start=1):
        learned = run.arm_status.get(RING_DOWNS_KEY)
        start = driver.publish(command, LEAD_S)
        shaped = driver.wait_for_shaped(number, SHAPE_TIMEOUT_S)
        added = float(shaped.time_s[-1] - command.time_s[-1])
        moved = CommandedMove(command, added, None if learned is None else int(learned))
        run.commanded.append(moved)
        end = start + float(shaped.time_s[-1])
        gap = settle_gap(model, command.angles_rad[-1])
        run.echo(
            f'  move {number}: {moved.label}, '
            f'{moved.shaped_by}' + (f' (+{added:.3f} s)' if moved.shaped else '')
        )
        what = f'the arm did not ring down after move {number}'
        driver.wait_for_tip(end + gap - LEAD_S, what, gap + RECORD_TIMEOUT_S)
    driver.wait_for_tip(
        end + WINDOW_S + 0.5, 'the arm did not ring down after the last move', RECORD_TIMEOUT_S
    )


def residuals(run: WorkspaceDemoRun) -> None:
    """Each move's residual on the recorded arm, and the two simulated references.

    Raises:
        LumpbeamError: The record holds another number of moves than were commanded.
    """
    measured = bag_move_residuals(
        run.recorded_bag, run.real, TIP_POSE_TRUTH, joints_topic=REAL_ARM_JOINT_STATES
    )
    if len(measured) != len(run.commanded):
        raise LumpbeamError(
            f'{run.recorded_bag}: {len(measured)} move(s) recorded, {len(run.commanded)} commanded'
        )
    arm = ArmModel.from_config(run.real)
    by_file = WorkspaceShaper(run.nominal, SHAPER, DEFAULT_MAX_MODES, tune=True)
    run.outcomes = []
    for number, (moved, residual) in enumerate(zip(run.commanded, measured, strict=True), 1):
        file_shaped = shape_trajectory(moved.command, by_file.shape_move(moved.command).impulses)
        run.outcomes.append(
            MoveOutcome(
                number,
                moved,
                residual,
                predicted_residual(arm, moved.command),
                predicted_residual(arm, file_shaped),
            )
        )


def figure(run: WorkspaceDemoRun) -> None:
    """Draws each move's residuals (``figures/`` + :data:`FIGURE_NAME`)."""
    from lumpbeam_ros.apps.plots.shaping import plot_workspace_outcome

    run.figure = plot_workspace_outcome(run.outcomes, run.out / 'figures' / FIGURE_NAME)
    run.echo(f'  wrote {run.figure}')


def table(outcomes: list[MoveOutcome]) -> list[str]:
    """The moves as text: residuals (mm) on the arm, and the reduction against unshaped."""
    lines = [
        'residual vibration of the arm (RMS over the 3 s after each move, mm)',
        f'  {"move":<4} {"":<34} {"shaped by":<24} {"measured":>9} {"unshaped":>9} '
        f'{"less":>7} {"file model":>10}',
    ]
    for outcome in outcomes:
        moved = outcome.commanded
        lines.append(
            f'  {outcome.number:<4} {moved.label:<34} {moved.shaped_by:<24} '
            f'{1e3 * outcome.measured.residual_m:9.4f} {1e3 * outcome.unshaped_m:9.4f} '
            f'{100 * outcome.reduction:6.2f}% {1e3 * outcome.file_model_m:10.4f}'
        )
    return lines


def learned_links(nominal: ArmConfig, real: ArmConfig, status: Mapping[str, str]) -> list[str]:
    """Each link's clamp stiffness in the file and learned, off the arm's by how much."""
    learned = arm_from_status(0, dict(status), nominal)
    lines = []
    for i, (file, fit, truth) in enumerate(
        zip(nominal.links, learned.links, real.links, strict=True), start=1
    ):
        k = [link_stiffness_total(link) for link in (file, fit, truth)]
        lines.append(
            f'  link {i}: stiffness in the file {k[0] / k[2] - 1:+.1%} off the arm, learned '
            f'{k[1] / k[2] - 1:+.3%}'
        )
    return lines


def summarize(run: WorkspaceDemoRun) -> None:
    """Prints the table, writes ``summary.json``; fails when learning did not pay.

    Raises:
        LumpbeamError: No move was shaped by the learned arm, or one of them rang less than
            :data:`MIN_REDUCTION` less than unshaped.
    """
    learned = [o for o in run.outcomes if o.commanded.shaped]
    run.summary = {
        'arm_config': str(run.options.arm_config),
        'real_arm': str(run.real_file),
        'arm_params': typed_values(run.arm_status),
        'moves': [o.as_json() for o in run.outcomes],
        'least_reduction_learned': min((o.reduction for o in learned), default=math.nan),
        'figure': str(run.figure),
        'recorded_bag': str(run.recorded_bag),
        'step_seconds': dict(run.step_seconds),
    }
    write_json(run.out / 'summary.json', run.summary)
    if run.arm_status:
        run.echo(f'links learned from {run.arm_status.get(RING_DOWNS_KEY)} ring-down(s):')
        for line in learned_links(run.nominal, run.real, run.arm_status):
            run.echo(line)
    for line in table(run.outcomes):
        run.echo(line)
    if not learned:
        raise LumpbeamError(
            f'the identifier learned no arm on /arm_params: every move went unshaped '
            f'(logs: {run.log_dir})'
        )
    worst = min(learned, key=lambda o: o.reduction)
    if worst.reduction < MIN_REDUCTION:
        raise LumpbeamError(
            f'move {worst.number}, shaped by the learned arm, rang {100 * worst.reduction:.1f} % '
            f'less than unshaped, under the {100 * MIN_REDUCTION:.0f} % expected (see '
            f'{run.figure})'
        )


WorkspaceStep = tuple[str, Callable[[WorkspaceDemoRun], None]]


def workspace_steps() -> list[WorkspaceStep]:
    """The workspace demo's steps, in order."""
    return [('loop', loop), ('residuals', residuals), ('figure', figure), ('summary', summarize)]


def run_workspace_demo(
    options: WorkspaceDemoOptions, echo: Callable[[str], None] = print
) -> WorkspaceDemoRun:
    """Runs the workspace demo's steps in order.

    Args:
        options: The arm file, output folder, domain.
        echo: Where progress and the table go.

    Returns:
        The filled-in run.

    Raises:
        ConfigError: The arm file is missing or malformed.
        LumpbeamError: Not a two-link arm, a step failed (its child processes are stopped
            first), or learning did not pay (:func:`summarize`).
    """
    nominal = load_arm_config(options.arm_config)
    run = WorkspaceDemoRun(options=options, nominal=nominal, real=real_arm(nominal), echo=echo)
    run_steps(run, workspace_steps(), run.step_seconds, echo)
    return run
