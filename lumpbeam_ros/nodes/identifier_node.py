"""The identifier node: live frequency, damping and stiffness on ``/beam_params``.

Subscribes to ``/tip_pose`` (PoseStamped in ``beam_base``) and ``/tip_load`` (Float64, kg,
reliable and transient local as :mod:`lumpbeam_ros.core.bagio.qos` gives it), keeps the last
``window.length_s`` of poses in a :class:`~lumpbeam_ros.core.ident.window.SlidingWindow`, and on
a timer at ``publish_rate_hz`` identifies the window
(:func:`~lumpbeam_ros.core.ident.identify.identify_from`, warm-started from the last update) and
publishes one DiagnosticStatus ``lumpbeam/identifier`` (doc/interfaces.md, 'Topics').

On an arm (once ``/joint_states`` arrives) the free vibration is each move's ring-down: it
starts where the joints stop (:class:`~lumpbeam_ros.core.ident.ring_down.RestTracker`) in place
of a load release, and the tip is taken along its swing. Given ``arm_config``, each ring-down
that has lasted ``arm_fit_after_s`` joins the arm's fit
(:class:`~lumpbeam_ros.core.ident.arm.learner.ArmLearner`): the links (or with ``fit_payload``
the payload) fitted to every ring-down so far are published on ``/arm_params`` (status
``lumpbeam/arm``, latched).

Parameters: :data:`~lumpbeam_ros.nodes.params.identifier_params.IDENTIFIER_SCHEMA`
(``doc/parameters.md``). Run it with the package's settings, on sim time when a bag is
replayed::

    identifier_node --ros-args --params-file config/identifier.yaml -p use_sim_time:=true

Bad input never stops it: a pose in another frame is dropped with a throttled warning,
NaN/inf and out-of-order or repeated stamps are dropped and counted, a clock that jumps
back (a looping bag) empties the window.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Sequence
from typing import Unpack

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import PoseStamped
from sensor_msgs.msg import JointState
from std_msgs.msg import Float64

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import (
    ARM_PARAMS,
    ARM_STATUS,
    BASE_FRAME,
    BEAM_PARAMS,
    IDENTIFIER_STATUS,
    JOINT_STATES,
    TIP_LOAD,
    TIP_POSE,
)
from lumpbeam_ros.core.bagio.convert import joint_state_values, pose_values
from lumpbeam_ros.core.ident.arm.learner import ArmEstimate, ArmLearner
from lumpbeam_ros.core.ident.assembly import FitState
from lumpbeam_ros.core.ident.identification import Identification, Status
from lumpbeam_ros.core.ident.identify import identify_live
from lumpbeam_ros.core.ident.ring_down import RestTracker
from lumpbeam_ros.core.ident.settings import (
    IDENTIFIER_SETTINGS,
    IdentifierConfig,
    config_from_parameters,
)
from lumpbeam_ros.core.ident.window import SlidingWindow
from lumpbeam_ros.core.model.arm.config import load_arm_config
from lumpbeam_ros.core.model.parameters import BeamParameters, load_beam_config
from lumpbeam_ros.core.model.statics import carries
from lumpbeam_ros.nodes.endpoints import publisher, subscription
from lumpbeam_ros.nodes.lifecycle import run_node, spin_live
from lumpbeam_ros.nodes.params.identifier_params import IDENTIFIER_SCHEMA
from lumpbeam_ros.nodes.ros_parameters import NodeOptions, SchemaNode

#: Seconds between repeated warnings about the same kind of bad input.
WARN_PERIOD_S = 5.0


class IdentifierNode(SchemaNode):
    """Publishes ``/beam_params`` from ``/tip_pose`` and ``/tip_load``.

    Args:
        **options: See :class:`~lumpbeam_ros.nodes.ros_parameters.NodeOptions`.

    Raises:
        ConfigError: A parameter (window, fit, release, rates) or the beam file is invalid.
    """

    def __init__(self, **options: Unpack[NodeOptions]):
        super().__init__(IDENTIFIER_SCHEMA, **options)
        values = self.parameter_values
        settings = {spec.name: values[spec.name] for spec in IDENTIFIER_SETTINGS}
        self.config: IdentifierConfig = config_from_parameters(
            settings, f'{self.get_name()} parameters'
        )
        beam_file = str(values['beam_config'])
        self.beam: BeamParameters = load_beam_config(beam_file or None)[0]
        self._carried_kg = math.nan  # the last load reading found carried (checked once)
        self.hardware_id = str(values['hardware_id'])
        self.window = SlidingWindow.from_config(self.config)
        self.joints = RestTracker(self.config.rest_tolerance_rad)
        self.bad_joint_states = 0
        self._state: FitState | None = None
        self._resets = 0
        self.wrong_frame = 0
        self.updates = 0
        self._output = publisher(self, DiagnosticArray, BEAM_PARAMS)
        subscription(self, PoseStamped, TIP_POSE, self._on_pose)
        subscription(self, Float64, TIP_LOAD, self._on_load)
        subscription(self, JointState, JOINT_STATES, self._on_joint_state)
        self.learner: ArmLearner | None = None
        self.arm_updates = 0
        if values['arm_config']:
            self.learner = ArmLearner(
                load_arm_config(str(values['arm_config'])),
                bool(values['fit_payload']),
                float(values['arm_fit_after_s']),
            )
            self._arm_output = publisher(self, DiagnosticArray, ARM_PARAMS)
        self.create_timer(1.0 / self.config.publish_rate_hz, self._on_timer)

    def _on_pose(self, msg: PoseStamped) -> None:
        if msg.header.frame_id != BASE_FRAME:
            self.wrong_frame += 1
            self.get_logger().warning(
                f'/tip_pose in frame {msg.header.frame_id!r}, expected {BASE_FRAME!r}: '
                f'dropped ({self.wrong_frame} so far)',
                throttle_duration_sec=WARN_PERIOD_S,
            )
            return
        try:
            stamp_ns, x, z, pitch, _ = pose_values(msg)
        except LumpbeamError:
            # An invalid quaternion: the window counts it with the other non-finite samples.
            stamp_ns, x, z, pitch = 0, math.nan, math.nan, math.nan
        self.window.push(stamp_ns * 1e-9, z, pitch, x)
        counts = self.window.counts
        if counts.resets != self._resets:
            self._resets = counts.resets
            self._state = None
            self.joints.clear()
            if self.learner is not None:
                self.learner.clear()
            self.get_logger().warning(
                'tip pose stamps jumped back (a looping bag?): window emptied',
                throttle_duration_sec=WARN_PERIOD_S,
            )

    def _on_load(self, msg: Float64) -> None:
        # Float64 has no stamp: the reading only hints at a release, timed from the poses.
        now = self.get_clock().now().nanoseconds * 1e-9
        kg = float(msg.data)
        if math.isfinite(kg) and kg >= 0.0 and kg != self._carried_kg:
            if not carries(self.beam, kg):
                self.refuse(
                    TIP_LOAD,
                    f'{msg.data!r} kg refused: the beam cannot carry it (no static equilibrium, '
                    'or a sag past a tenth of its length); a wrong reading would make its '
                    'stiffness (B.12)',
                    f'keeping {self._carried_kg:g} kg',
                )
                return
            self._carried_kg = kg
        stored, stamp = self.window.push_load_on_arrival(msg.data, now)
        if not stored:
            self.refuse(
                TIP_LOAD,
                f'{msg.data!r} kg at {stamp:.3f} s refused (not a finite mass >= 0, or older '
                'than the last reading)',
                'keeping the last reading',
            )

    def _on_joint_state(self, msg: JointState) -> None:
        stamp_ns, names, positions = joint_state_values(msg)
        # A malformed message (names and positions that do not pair up) is nobody's joints:
        # taken, it would switch the node to an arm for good.
        if len(names) != positions.size or not self.joints.push(stamp_ns * 1e-9, positions):
            self.bad_joint_states += 1
            self.refuse(
                JOINT_STATES,
                f'joint state at {stamp_ns * 1e-9:.3f} s refused: {len(names)} names for '
                f'{positions.size} positions, a position that is not finite, a stamp going '
                'back or another number of joints',
                'keeping the joints as they were',
            )

    def _on_timer(self) -> None:
        self.updates += 1
        result, self._state = identify_live(
            self.window.snapshot(), self.beam, self.config, self._state, self.joints
        )
        self._output.publish(self.diagnostics(result))
        if self.learner is not None:
            estimate = self.learner.offer(self.joints.current, result)
            if estimate is not None:
                self._publish_arm(estimate)

    def _publish_arm(self, estimate: ArmEstimate) -> None:
        """Publishes the arm's fit on ``/arm_params`` and logs it."""
        status = DiagnosticStatus(
            level=bytes([int(estimate.status)]),
            name=ARM_STATUS,
            message=estimate.message,
            hardware_id=self.hardware_id,
            values=[KeyValue(key=k, value=v) for k, v in estimate.key_values()],
        )
        msg = DiagnosticArray(status=[status])
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.header.frame_id = BASE_FRAME
        self._arm_output.publish(msg)
        self.arm_updates += 1
        # rclpy ties a severity to each call site: one call for both levels raises.
        if estimate.status == Status.OK:
            self.get_logger().info(f'{ARM_PARAMS}: {estimate.message}')
        else:
            self.get_logger().warning(f'{ARM_PARAMS}: {estimate.message}')

    def diagnostics(self, result: Identification) -> DiagnosticArray:
        """The ``/beam_params`` message of one identification (doc/interfaces.md, 'Topics').

        Args:
            result: The identification.

        Returns:
            A DiagnosticArray with one status, stamped now.
        """
        counts = self.window.counts
        message = result.message
        dropped = counts.note()
        if dropped:
            # The counts are also published as values; the message says it to a reader.
            message = f'{message}; /tip_pose: {dropped}'
        pairs: Sequence[tuple[str, str]] = [
            *result.key_values(),
            ('samples_wrong_frame', str(self.wrong_frame)),
            ('samples_non_finite', str(counts.non_finite)),
            ('samples_out_of_order', str(counts.out_of_order + counts.duplicates)),
            ('window_resets', str(counts.resets)),
            ('joint_states_ignored', str(self.bad_joint_states)),
        ]
        status = DiagnosticStatus(
            level=bytes([int(result.status)]),
            name=IDENTIFIER_STATUS,
            message=message,
            hardware_id=self.hardware_id,
            values=[KeyValue(key=k, value=v) for k, v in pairs],
        )
        msg = DiagnosticArray(status=[status])
        msg.header.stamp = self.get_clock().now().to_msg()
        msg.header.frame_id = BASE_FRAME
        return msg


def main(args: Sequence[str] | None = None) -> int:
    """Runs the node until Ctrl-C (console script ``identifier_node``).

    On wall time it spins on rclpy's events executor, which takes each pose without
    rebuilding a wait set (:func:`~lumpbeam_ros.nodes.lifecycle.spin_live`).

    Args:
        args: Command-line arguments (default ``sys.argv``), incl. ``--ros-args``.

    Returns:
        0, or 2 when the configuration is invalid (one line on stderr).
    """
    return run_node(
        IDENTIFIER_SCHEMA.node,
        IdentifierNode,
        lambda node: {BEAM_PARAMS: node.updates, ARM_PARAMS: node.arm_updates},
        args,
        run=spin_live,
    )


if __name__ == '__main__':
    sys.exit(main())
