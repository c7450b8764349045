"""The shaper node: ``/joint_trajectory`` shaped onto ``/joint_trajectory_shaped``.

Each JointTrajectory received is convolved with an input shaper
(:mod:`lumpbeam_ros.core.shaping`) and published with the same header and joint names, its
points (positions only) at 1 kHz or the input's rate if finer, ending the shaper's duration
later. The shaper cancels:

- ``source: beam_params``: the modes of the latest valid ``/beam_params`` estimate (status
  ``lumpbeam/identifier``; up to ``max_modes``; ``shaper``, or ``robust_shaper`` when an
  identified frequency's relative standard deviation exceeds ``robust_above``);
- ``source: parameters``: one mode fixed by ``frequency_hz`` and ``damping_ratio``;
- ``source: model``: each move of the trajectory, for the first ``max_modes`` modes of the
  arm's model at that move's end (:class:`~lumpbeam_ros.core.shaping.workspace.WorkspaceShaper`,
  ``tune`` as ``lumpbeam shape --tune``), the arm being ``arm_config``'s until a status
  ``lumpbeam/arm`` of level OK on ``/arm_params`` gives the identified links (or payload).

An invalid estimate or arm (level ERROR, or WARN for the arm; a value missing or not finite,
a standard deviation larger than its value, a mode no shaper can serve:
:class:`~lumpbeam_ros.core.shaping.limits.ShapingLimits` with ``max_added_s``) never makes a
shaper: the node keeps the last good one and warns (throttled).
Until it has a first one it publishes nothing, and warns for each trajectory dropped: a
consumer of ``/joint_trajectory_shaped`` relies on the commands being shaped, and an unshaped
move published there would ring while claiming not to; the unshaped command stays on
``/joint_trajectory`` for whoever wants it. ``unshaped_until_estimate: true`` forwards it
unshaped instead (a first move that rings to be identified); with ``source: model`` it
forwards every move unshaped until the first identified arm, the file's model shaping none.
A trajectory that cannot be shaped (fewer than 2 points, times that do not increase,
positions missing or not finite, longer than ``max_command_s``) is dropped with a throttled
warning.

Parameters: :data:`~lumpbeam_ros.nodes.params.shaper_params.SHAPER_SCHEMA`
    (``doc/parameters.md``)::

    shaper_node --ros-args --params-file config/shaper.yaml
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from typing import Unpack

from diagnostic_msgs.msg import DiagnosticArray
from trajectory_msgs.msg import JointTrajectory as JointTrajectoryMsg

from lumpbeam_ros.base.errors import ConfigError, LumpbeamError
from lumpbeam_ros.base.interface import (
    ARM_PARAMS,
    ARM_STATUS,
    BEAM_PARAMS,
    IDENTIFIER_STATUS,
    JOINT_TRAJECTORY,
    JOINT_TRAJECTORY_SHAPED,
)
from lumpbeam_ros.core.ident.arm.learner import arm_from_status
from lumpbeam_ros.core.model.arm.config import ArmConfig, load_arm_config
from lumpbeam_ros.core.shaping.apply import shape_trajectory
from lumpbeam_ros.core.shaping.estimate import choose_shaper, estimate_from_status
from lumpbeam_ros.core.shaping.impulses import Impulses, Mode
from lumpbeam_ros.core.shaping.limits import ShapingLimits
from lumpbeam_ros.core.shaping.shapers import design_shaper
from lumpbeam_ros.core.shaping.workspace import WorkspaceShaper
from lumpbeam_ros.nodes.endpoints import publisher, subscription
from lumpbeam_ros.nodes.lifecycle import run_node
from lumpbeam_ros.nodes.params.shaper_params import SHAPER_SCHEMA
from lumpbeam_ros.nodes.ros_parameters import NodeOptions, SchemaNode
from lumpbeam_ros.nodes.trajectory_messages import (
    command_subscription,
    trajectory_from_msg,
    trajectory_msg,
)

#: Seconds between repeated warnings about the same kind of bad input.
WARN_PERIOD_S = 5.0


class ShaperNode(SchemaNode):
    """Publishes ``/joint_trajectory_shaped`` from ``/joint_trajectory`` (and ``/beam_params``).

    Args:
        **options: See :class:`~lumpbeam_ros.nodes.ros_parameters.NodeOptions`.

    Attributes:
        impulses: The shaper in use (``None`` until the first valid estimate).
        description: What it cancels, e.g. ``'ZV for 3.2 Hz (zeta 0.01)'``.
        published: Shaped trajectories published.
        dropped: Trajectories received and not published.

    Raises:
        ConfigError: A parameter is invalid.
    """

    def __init__(self, **options: Unpack[NodeOptions]):
        super().__init__(SHAPER_SCHEMA, **options)
        values = self.parameter_values
        self.impulses: Impulses | None = None
        self.description = ''
        self.published = 0
        self.dropped = 0
        self._unshaped_first = bool(values['unshaped_until_estimate'])
        self.limits = ShapingLimits(float(values['max_added_s']), float(values['max_command_s']))
        self._output = publisher(self, JointTrajectoryMsg, JOINT_TRAJECTORY_SHAPED)
        command_subscription(self, JOINT_TRAJECTORY, self._on_trajectory, self._drop)
        self.workspace: WorkspaceShaper | None = None
        if values['source'] == 'parameters':
            mode = Mode(float(values['frequency_hz']), float(values['damping_ratio']))
            self._adopt(str(values['shaper']), [mode])
        elif values['source'] == 'model':
            if not values['arm_config']:
                raise ConfigError(
                    f'{self.get_name()} parameters', 'arm_config', 'needed with source model'
                )
            self.nominal = load_arm_config(str(values['arm_config']))
            if not self._unshaped_first:
                self._adopt_arm(self.nominal, f'the arm file {values["arm_config"]}')
            subscription(self, DiagnosticArray, ARM_PARAMS, self._on_arm)
        else:
            subscription(self, DiagnosticArray, BEAM_PARAMS, self._on_params)

    def _adopt_arm(self, arm: ArmConfig, source: str) -> None:
        values = self.parameter_values
        self.workspace = WorkspaceShaper(
            arm,
            str(values['shaper']),
            int(values['max_modes']),
            tune=bool(values['tune']),
            predict=False,
        )
        self.description = f'{str(values["shaper"]).upper()} by the model of {source}'
        self.get_logger().info(f'shaping each move with {self.description}')

    def _on_arm(self, msg: DiagnosticArray) -> None:
        for status in msg.status:
            if status.name != ARM_STATUS:
                continue
            pairs = {kv.key: kv.value for kv in status.values}
            try:
                arm = arm_from_status(status.level[0], pairs, self.nominal)
            except LumpbeamError as exc:
                kept = f'keeping {self.description}' if self.workspace else 'moves go unshaped'
                self.refuse(ARM_PARAMS, f'arm refused ({exc})', kept)
                continue
            self._adopt_arm(arm, f'{ARM_PARAMS} ({status.message})')

    def _adopt(self, kind: str, modes: Sequence[Mode]) -> None:
        impulses = design_shaper(kind, modes)
        self.limits.check_shaper(modes, impulses)
        description = f'{kind.upper()} for ' + ', '.join(
            f'{m.frequency_hz:.4g} Hz (zeta {m.damping_ratio:.3g})' for m in modes
        )
        if description != self.description:
            self.get_logger().info(
                f'shaping with {description}: {impulses.time_s.size} impulses, '
                f'{impulses.duration_s:.4f} s added'
            )
        self.impulses, self.description = impulses, description

    def _on_params(self, msg: DiagnosticArray) -> None:
        values = self.parameter_values
        for status in msg.status:
            if status.name != IDENTIFIER_STATUS:
                continue
            pairs = {kv.key: kv.value for kv in status.values}
            try:
                estimate = estimate_from_status(status.level[0], pairs, int(values['max_modes']))
                kind = choose_shaper(
                    estimate.modes,
                    str(values['shaper']),
                    str(values['robust_shaper']),
                    float(values['robust_above']),
                )
                self._adopt(kind, [m.mode for m in estimate.modes])
            except LumpbeamError as exc:
                kept = f'keeping {self.description}' if self.impulses else 'no shaper yet'
                self.refuse(BEAM_PARAMS, f'estimate refused ({exc})', kept)
                continue
            for note in estimate.left_out:
                self.get_logger().warning(
                    f'{BEAM_PARAMS}: {note}: left out', throttle_duration_sec=WARN_PERIOD_S
                )

    def _on_trajectory(self, msg: JointTrajectoryMsg) -> None:
        try:
            trajectory = trajectory_from_msg(msg)
            self.limits.check_command(trajectory)
            if self.workspace is not None:
                shaped, moves = self.workspace.shape(trajectory)
                for move in moves:
                    self.limits.check_shaper(move.modes, move.impulses)
            elif self.impulses is None:
                if not self._unshaped_first:
                    self._drop('no valid estimate yet: nothing published')
                    return
                self.get_logger().warning(
                    'no valid estimate yet: published unshaped',
                    throttle_duration_sec=WARN_PERIOD_S,
                )
                shaped = trajectory
            else:
                shaped = shape_trajectory(trajectory, self.impulses)
        except LumpbeamError as exc:
            self._drop(f'cannot shape it ({exc})')
            return
        self._output.publish(trajectory_msg(shaped, msg))
        self.published += 1

    def _drop(self, why: str) -> None:
        self.dropped += 1
        self.get_logger().warning(
            f'{JOINT_TRAJECTORY}: {why}; {self.dropped} dropped so far',
            throttle_duration_sec=WARN_PERIOD_S,
        )


def main(args: Sequence[str] | None = None) -> int:
    """Runs the node until Ctrl-C (console script ``shaper_node``).

    Args:
        args: Command-line arguments (default ``sys.argv``), incl. ``--ros-args``.

    Returns:
        0, or 2 when the configuration is invalid (one line on stderr).
    """
    return run_node(
        SHAPER_SCHEMA.node,
        ShaperNode,
        lambda node: {JOINT_TRAJECTORY_SHAPED: node.published},
        args,
    )


if __name__ == '__main__':
    sys.exit(main())
