"""``lumpbeam demo --arm FILE``: the input-shaping loop live on a simulated flexible arm.

An arm moves unshaped and rings; the identifier node identifies the modes of its ring-down;
the shaper node adopts them; the move back is shaped and rings far less. The steps:

1. ``loop``: the arm demos' live graph (:mod:`~lumpbeam_ros.apps.demo.arm_graph`), the
   shaper node with ``source: beam_params``, forwarding unshaped until its first estimate.
   This process publishes move 1 (out) on ``/joint_trajectory``, waits until an OK estimate
   is on ``/beam_params`` and the shaper has adopted it, publishes move 2 (back), which the
   shaper shapes, and stops the graph once the ring-down after move 2 is recorded.
2. ``residuals``: each move's residual vibration from the recorded ``/joint_states`` and
   ``/tip_pose`` (:func:`~lumpbeam_ros.core.shaping.loop.bag_move_residuals`).
3. ``figure`` and ``summary``: both residuals drawn, printed and written to ``summary.json``;
   the step fails (one line) when the shaped move rings less than 90 % less.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from lumpbeam_ros.apps.demo.arm_graph import (
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
    BEAM_PARAMS,
    DIAGNOSTIC_ARRAY,
    IDENTIFIER_STATUS,
    TIP_POSE_TRUTH,
)
from lumpbeam_ros.core.model.arm.config import ArmConfig, load_arm_config
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.model.arm.residual import WINDOW_S
from lumpbeam_ros.core.shaping.loop import ShapingOutcome, bag_move_residuals

#: What the shaper node logs when it adopts an estimate.
SHAPER_ADOPTED = 'shaping with'
#: Each move turns joint 1 by this much (the other joints stay at 0), rad ...
MOVE_RAD = 1.0
#: ... in this long (a minimum-jerk profile sampled at 1 kHz), s.
MOVE_S = 0.3
#: Commands are stamped this far ahead of their publication: both simulators (and the
#: shaper in between) receive them before they start, and start them at the same instant, s.
LEAD_S = 1.0
#: Recorded past each residual window, s.
MARGIN_S = 0.5
#: Move 2 waits until move 1's vibration has decayed to this fraction of its amplitude.
LEFT_RINGING = 0.02
#: ... but at most this long, s (a lightly damped arm would keep the demo waiting minutes).
MAX_GAP_S = 30.0
#: Longest wait for the identifier's OK estimate and the shaper's adoption after move 1, s.
ESTIMATE_TIMEOUT_S = 60.0
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


def the_moves(arm: ArmConfig) -> tuple[JointTrajectory, JointTrajectory]:
    """Move 1 (joint 1 out by :data:`MOVE_RAD`) and move 2 (back to where it started)."""
    near = np.zeros(arm.n_joints)
    far = near.copy()
    far[0] = MOVE_RAD
    return minimum_jerk(near, far, MOVE_S), minimum_jerk(far, near, MOVE_S)


def loop(run: ArmDemoRun) -> None:
    """Runs the live graph through both moves and records it (``out/bags/recorded``)."""
    run.recorded_bag = fresh_bags_dir(run.out / BAGS_DIR) / 'recorded'
    arm = run.options.arm_config
    spec = ArmGraph(
        real_arm=arm,
        model=arm,
        shaper_args=('-p', 'source:=beam_params', '-p', 'unshaped_until_estimate:=true'),
        recorded={BEAM_PARAMS: DIAGNOSTIC_ARRAY},
        readers={BEAM_PARAMS: 1},  # the shaper
    )
    run_arm_graph(spec, run, lambda driver: _drive(driver, run))


def _drive(driver: ArmDriver, run: ArmDemoRun) -> None:
    """Publishes the two moves, waiting for the estimate between them and the ring-down after.

    Raises:
        LumpbeamError: No OK estimate or no adoption in time, move 2 not shaped, the
            simulators not publishing, or a child exited.
    """
    from diagnostic_msgs.msg import DiagnosticArray

    from lumpbeam_ros.core.shaping.estimate import estimate_from_status

    move_out, move_back = the_moves(run.arm)
    seen: dict[str, Any] = {'ok': None}

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

    driver.listen(DiagnosticArray, BEAM_PARAMS, on_params)
    # Move 1: the shaper has no estimate yet and forwards it unshaped.
    start = driver.publish(move_out, LEAD_S)
    end_1 = start + float(move_out.time_s[-1])
    run.echo(f'  move 1: joint 1 to {MOVE_RAD:g} rad in {MOVE_S:g} s, unshaped')
    driver.wait_for_shaped(1)
    # The identifier's estimate of the ring-down, then the shaper's adoption of it, and
    # the whole residual window after move 1 before move 2 starts.
    seen['ok'] = None
    driver.spin_until(
        lambda: seen['ok'] is not None,
        ESTIMATE_TIMEOUT_S,
        'no OK estimate of the ring-down on /beam_params',
    )
    driver.wait_for_line('shaper', SHAPER_ADOPTED)
    run.echo(f'  identified after {driver.tip_s - end_1:.1f} s of ring-down: the shaper adopts it')
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
    driver.wait_for_tip(
        end_1 + gap - LEAD_S, 'the arm did not ring down after move 1', gap + RECORD_TIMEOUT_S
    )
    # Move 2: shaped with the latest estimate, which the shaper has adopted by now.
    run.estimate = dict(seen['ok'])
    start = driver.publish(move_back, LEAD_S)
    shaped = driver.wait_for_shaped(2)
    run.shaper_log = driver.wait_for_line('shaper', SHAPER_ADOPTED)
    run.echo(f'  identified: {_modes_text(run.estimate)}')
    run.echo(f'  shaper node: {run.shaper_log}')
    run.added_s = float(shaped.time_s[-1] - move_back.time_s[-1])
    if run.added_s <= 0.0:
        raise LumpbeamError('the shaper published move 2 unshaped')
    run.echo(f'  move 2: back to 0 rad, shaped ({run.added_s:.3f} s added)')
    end_2 = start + float(shaped.time_s[-1])
    driver.wait_for_tip(
        end_2 + WINDOW_S + MARGIN_S, 'the arm did not ring down after move 2', RECORD_TIMEOUT_S
    )


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
