"""The diagnosis node: the discrepancy workflow live, on ``/model_discrepancy``.

Subscribes to ``/tip_pose`` (PoseStamped in ``beam_base``), ``/tip_load`` (Float64, kg,
reliable and transient local) and ``/tip_pose_predicted`` (the simulator's prediction); keeps
them in a :class:`~lumpbeam_ros.core.diagnose.live.LiveBuffer`; on each completed ring-down (or
window) builds the record ``lumpbeam diagnose`` would build from a bag and runs the same
workflow in a worker (a process by default: a diagnosis takes seconds of CPU and the callbacks
must stay free). Publishes one DiagnosticStatus ``lumpbeam/diagnosis`` on
``/model_discrepancy`` (``doc/interfaces.md``) after each diagnosis and every
``status_period_s``.

With ``adopt`` it sets the simulator node's effect parameters (``effects.<name>.<parameter>``)
through the standard parameter service, so ``ros2 param get`` shows what was adopted, but
only when the augmented model's gap is smaller than the gap of the simulator's current
prediction over the same stretch. Parameters:
:data:`~lumpbeam_ros.nodes.params.diagnosis_params.DIAGNOSIS_SCHEMA` (``doc/parameters.md``)::

    diagnosis_node --ros-args --params-file config/diagnosis.yaml -p use_sim_time:=true

Bad input never stops it: poses in another frame or with NaN are dropped with a throttled
warning and counted; predicted poses without measured ones, a stretch without a release and a
failed diagnosis are said in the status (level STALE) and a throttled warning.
"""

from __future__ import annotations

import math
import multiprocessing
import os
import signal
import sys
from collections.abc import Mapping, Sequence
from multiprocessing.pool import AsyncResult, Pool, ThreadPool
from typing import Any, Unpack

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import PoseStamped
from rclpy.clock import Clock, ClockType
from rclpy.parameter import Parameter
from rclpy.parameter_client import AsyncParameterClient
from rclpy.task import Future as RclpyFuture
from std_msgs.msg import Float64

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import (
    BASE_FRAME,
    DIAGNOSIS_STATUS,
    MODEL_DISCREPANCY,
    SIMULATOR_NODE,
    TIP_LOAD,
    TIP_POSE,
    TIP_POSE_PREDICTED,
)
from lumpbeam_ros.base.schema import settings_from_parameters
from lumpbeam_ros.core.bagio.convert import pose_values
from lumpbeam_ros.core.diagnose.live import (
    STALE,
    LiveBuffer,
    LiveDiagnosis,
    LiveDiagnosisConfig,
    Stretch,
    diagnose_live,
    status_values,
)
from lumpbeam_ros.core.model.parameters import BeamParameters, load_beam_config
from lumpbeam_ros.nodes.endpoints import publisher, subscription
from lumpbeam_ros.nodes.lifecycle import run_node
from lumpbeam_ros.nodes.params.diagnosis_params import DIAGNOSIS_SCHEMA
from lumpbeam_ros.nodes.ros_parameters import NodeOptions, SchemaNode
from lumpbeam_ros.nodes.sent_time import sent_ns

#: Seconds between repeated warnings about the same kind of bad input.
WARN_PERIOD_S = 5.0
#: How much lower than the node's the worker process's scheduling priority is.
WORKER_NICENESS = 10
#: How often the node looks for a complete stretch and a finished diagnosis, s.
POLL_PERIOD_S = 0.1


def _start_worker() -> None:
    """Readies a worker process: the node's signals left to it, the CPU yielded, imports done.

    Ctrl-C is for the node, which then ends the worker; so is a signal to the node's process
    group, which the worker leaves (it ends with the node all the same: its task pipe
    closes). A diagnosis is background work: at a lower priority it does not starve the
    nodes that must keep up with the stream (a camera node tracking frames) on a machine
    with few cores. The import is done now rather than
    when the first diagnosis waits for it.
    """
    # A signal to the node's process group (a terminal's Ctrl-C, a launcher's SIGTERM) is the
    # node's to act on: it ends the worker itself. Killed by it here, the worker would be
    # started again by the pool while the node stops, and the node would wait on the new one.
    os.setpgrp()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    os.nice(WORKER_NICENESS)
    import lumpbeam_ros.core.diagnose.workflow  # noqa: F401


class DiagnosisNode(SchemaNode):
    """Publishes ``/model_discrepancy`` from the measured and predicted tip and the load.

    Args:
        **options: See :class:`~lumpbeam_ros.nodes.ros_parameters.NodeOptions`.

    Raises:
        ConfigError: A parameter or the beam configuration is invalid.
    """

    def __init__(self, **options: Unpack[NodeOptions]):
        super().__init__(DIAGNOSIS_SCHEMA, self._on_change, **options)
        values = self.parameter_values
        self.adopt = bool(values['adopt'])
        self.hardware_id = str(values['hardware_id'])
        self.beam: BeamParameters = load_beam_config(values['beam_config'] or None)[0]
        self.buffer = LiveBuffer(
            settings_from_parameters(LiveDiagnosisConfig, values, f'{self.get_name()} parameters')
        )
        self.wrong_frame = 0
        self.non_finite = 0
        self.diagnoses = 0
        self.last: LiveDiagnosis | None = None
        self.adoption = 'not asked'  # what became of the last adoption, for the status
        self._problem: str | None = None  # why the last stretch was not diagnosed
        self._running: tuple[Stretch, float, AsyncResult[LiveDiagnosis]] | None = None
        # The time line (count of clock resets) self.last was first published on.
        self._verdict_line = 0
        self._pool = self._make_pool(values['worker'])
        # Not `_parameters`: that is rclpy's own table of this node's parameters.
        self._simulator_parameters = AsyncParameterClient(self, values[SIMULATOR_NODE])

        self._output = publisher(self, DiagnosticArray, MODEL_DISCREPANCY)
        # Two-argument callbacks: rclpy passes each message's info (its source timestamp).
        subscription(self, PoseStamped, TIP_POSE, lambda msg, info: self._on_pose(msg, info))
        subscription(self, PoseStamped, TIP_POSE_PREDICTED, self._on_predicted)
        subscription(self, Float64, TIP_LOAD, lambda msg, info: self._on_load(msg, info))
        #: Statuses published on ``/model_discrepancy``.
        self.published = 0
        self._heard = False  # any input yet
        # Steady timers: under use_sim_time a stopped /clock (a bag that ended) must not
        # stop the node from collecting a diagnosis and saying so.
        steady = Clock(clock_type=ClockType.STEADY_TIME)
        self.create_timer(POLL_PERIOD_S, self._poll, clock=steady)
        self.create_timer(values['status_period_s'], self._publish_status, clock=steady)

    @staticmethod
    def _make_pool(worker: str) -> Pool:
        if worker == 'thread':
            return ThreadPool(1)
        # spawn: a forked copy of a process running DDS threads is not safe.
        return multiprocessing.get_context('spawn').Pool(1, initializer=_start_worker)

    # -- callbacks ----------------------------------------------------------------------------

    def _pose(self, msg: PoseStamped, topic: str) -> tuple[float, float, float] | None:
        if msg.header.frame_id != BASE_FRAME:
            self.wrong_frame += 1
            self.get_logger().warning(
                f'{topic} in frame {msg.header.frame_id!r}, expected {BASE_FRAME!r}: dropped '
                f'({self.wrong_frame} so far)',
                throttle_duration_sec=WARN_PERIOD_S,
            )
            return None
        try:
            stamp_ns, _, z, pitch, _ = pose_values(msg)
        except LumpbeamError:
            stamp_ns, z, pitch = 0, math.nan, math.nan
        if not all(math.isfinite(v) for v in (z, pitch)):
            self.non_finite += 1
            self.get_logger().warning(
                f'{topic} with a non-finite position or orientation: dropped '
                f'({self.non_finite} so far)',
                throttle_duration_sec=WARN_PERIOD_S,
            )
            return None
        return stamp_ns * 1e-9, z, pitch

    def _on_pose(self, msg: PoseStamped, info: Mapping[str, int] | None = None) -> None:
        self._heard = True
        pose = self._pose(msg, TIP_POSE)
        if pose is None:
            return
        stored = self.buffer.push_measured(*pose, sent_s=self._sent_s(info))
        if not stored and not self.buffer.measured.holding:
            late = self.buffer.measured.counts
            self.get_logger().warning(
                f'/tip_pose with a repeated or out-of-order stamp: dropped '
                f'({late.duplicates + late.out_of_order} so far)',
                throttle_duration_sec=WARN_PERIOD_S,
            )

    def _on_predicted(self, msg: PoseStamped) -> None:
        self._heard = True
        pose = self._pose(msg, TIP_POSE_PREDICTED)
        if pose is not None:
            self.buffer.push_predicted(*pose)

    def _on_load(self, msg: Float64, info: Mapping[str, int] | None = None) -> None:
        self._heard = True
        kg = float(msg.data)
        if not math.isfinite(kg) or kg < 0.0:
            self.get_logger().warning(
                f'/tip_load {kg!r} rejected: not a mass', throttle_duration_sec=WARN_PERIOD_S
            )
            return
        # Float64 has no stamp: the buffer dates the change by when it was sent.
        self.buffer.push_load(self._sent_s(info), kg)

    def _sent_s(self, info: Mapping[str, int] | None) -> float:
        """When a message was sent: its DDS source timestamp, else the node's clock now.

        The sender's wall clock is free of the executor's delays and of a /clock that moved
        on while the message waited.
        """
        sent = sent_ns(info)
        if sent > 0:
            return sent * 1e-9
        return float(self.get_clock().now().nanoseconds) * 1e-9

    def _on_change(self, changes: Mapping[str, Any]) -> str | None:
        if 'adopt' in changes:
            self.adopt = bool(changes['adopt'])
        return None

    def _poll(self) -> None:
        if self._running is not None:
            self._collect()
        if self._running is not None:
            return
        stretch = self.buffer.next_stretch()
        if stretch is None:
            return
        try:
            record = self.buffer.record(stretch)
        except LumpbeamError as exc:
            self._problem = f'not diagnosed: {exc}'
            self.get_logger().warning(self._problem, throttle_duration_sec=WARN_PERIOD_S)
            self._publish_status()
            return
        current = self.buffer.prediction_gap(stretch.start_s, stretch.end_s)
        future = self._pool.apply_async(diagnose_live, (record, self.beam, stretch))
        self._running = (stretch, current, future)
        self.get_logger().info(
            f'diagnosing {stretch.start_s:.3f} to {stretch.end_s:.3f} s ({len(record)} poses)'
        )

    def _collect(self) -> None:
        assert self._running is not None
        stretch, current, future = self._running
        if not future.ready():
            return
        self._running = None
        try:
            result = future.get()
        except Exception as exc:  # noqa: BLE001 - a worker's failure must not stop the node
            self._problem = (
                f'diagnosis of {stretch.start_s:.3f} to {stretch.end_s:.3f} s failed: {exc}'
            )
            self.get_logger().warning(self._problem, throttle_duration_sec=WARN_PERIOD_S)
            self._publish_status()
            return
        self.diagnoses += 1
        self.last, self._problem, self._verdict_line = result, None, self._time_line()
        names = ','.join(name for name, _ in result.missing_effects) or result.missing_effect
        self.get_logger().info(
            f'diagnosis: {names} {result.effect_parameters}; gap rms '
            f'{result.gap_before_rms_m:.3e} m before, {result.gap_after_rms_m:.3e} m after; '
            f'simulator {current:.3e} m ({result.seconds:.1f} s)'
        )
        self.offer_adoption(result, current)
        self._publish_status()

    # -- adoption -----------------------------------------------------------------------------

    def offer_adoption(self, result: LiveDiagnosis, current_gap_m: float) -> None:
        """Sets the simulator's effect parameters to a diagnosis's when it fits better.

        Args:
            result: The diagnosis.
            current_gap_m: RMS gap of the simulator's prediction over the same stretch, m.
        """
        if not self.adopt:
            self.adoption = 'off'
            return
        values = result.simulator_parameters()
        if not values:
            self.adoption = 'nothing to adopt'
            return
        if not math.isfinite(current_gap_m):
            self.adoption = 'not adopted: no simulator prediction over the stretch to compare'
            self.get_logger().warning(self.adoption)
            return
        if result.gap_after_rms_m >= current_gap_m:
            self.adoption = (
                f'not adopted: the augmented model ({result.gap_after_rms_m:.3e} m) fits no '
                f"better than the simulator's prediction ({current_gap_m:.3e} m)"
            )
            self.get_logger().warning(self.adoption)
            return
        if not self._simulator_parameters.services_are_ready():
            self.adoption = f'not adopted: {self._simulator_parameters.remote_node_name} not found'
            self.get_logger().warning(self.adoption)
            return
        parameters = [Parameter(name, value=value) for name, value in values.items()]
        future = self._simulator_parameters.set_parameters(parameters)
        self.adoption = 'asked'
        future.add_done_callback(lambda f: self._adopted(f, values))

    def _adopted(self, future: RclpyFuture, values: Mapping[str, float]) -> None:
        node = self._simulator_parameters.remote_node_name
        try:
            results = future.result().results
        except Exception as exc:  # noqa: BLE001 - a failed service call is reported
            results, reason = [], str(exc)
        refused = [
            f'{name}: {r.reason or "refused"}'
            for name, r in zip(values, results, strict=False)
            if not r.successful
        ]
        if not results:
            refused = [reason or 'no answer']
        if refused:
            self.adoption = f'{node} refused the adoption: {"; ".join(refused)}'
            self.get_logger().warning(self.adoption)
        else:
            shown = ', '.join(f'{k}={v:.4g}' for k, v in values.items())
            self.adoption = f'adopted by {node}: {shown}'
            self.get_logger().info(self.adoption)
        self._publish_status()

    # -- output -------------------------------------------------------------------------------

    def _time_line(self) -> int:
        """Which time line the stream is on: the times its clock went back."""
        return self.buffer.measured.counts.resets

    def _late(self) -> int:
        """Measured poses dropped for a repeated stamp or one before the newest."""
        counts = self.buffer.measured.counts
        return counts.duplicates + counts.out_of_order

    def status(self) -> DiagnosticStatus:
        """The current ``lumpbeam/diagnosis`` status.

        Returns:
            The last diagnosis's (its level, effects and gaps), or STALE with what the node
            is waiting for or why the last stretch was not diagnosed.
        """
        missing = self.buffer.missing_input()
        counts = [
            ('diagnoses', str(self.diagnoses)),
            ('samples_wrong_frame', str(self.wrong_frame)),
            ('samples_non_finite', str(self.non_finite)),
            ('samples_out_of_order', str(self._late())),
        ]
        if missing is not None:
            if self.buffer.predicted_count:
                self.get_logger().warning(missing, throttle_duration_sec=WARN_PERIOD_S)
            level, message, pairs = STALE, missing, [('missing_input', missing.split(':')[0])]
        elif self._problem is not None:
            level, message, pairs = STALE, self._problem, []
        elif self.last is not None:
            level, message, pairs = status_values(self.last)
            pairs = [*pairs, ('adoption', self.adoption)]
            if self._verdict_line != self._time_line():
                # Repeated as new it would vouch for data the node no longer has.
                level = STALE
                message = (
                    'the clock went back since the last diagnosis, waiting for the next '
                    f'ring-down (last: {message})'
                )
        else:
            waiting = 'a load change' if not self.buffer.loads[1:] else 'the ring-down to end'
            if self._running is not None:
                waiting = 'the diagnosis running'
            level, message, pairs = STALE, f'waiting for {waiting}', []
        return DiagnosticStatus(
            level=bytes([level]),
            name=DIAGNOSIS_STATUS,
            message=message,
            hardware_id=self.hardware_id,
            values=[KeyValue(key=k, value=v) for k, v in [*pairs, *counts]],
        )

    def _publish_status(self) -> None:
        if not self._heard:
            # Statuses start with the first input: before it, no subscriber may have found
            # this node yet, and a graph's count of what was sent would not add up.
            return
        msg = DiagnosticArray(status=[self.status()])
        msg.header.stamp = self.get_clock().now().to_msg()
        self._output.publish(msg)
        self.published += 1

    def destroy_node(self) -> None:
        """Stops the worker (a running diagnosis is abandoned), then the node."""
        self._pool.terminate()
        super().destroy_node()


def main(args: Sequence[str] | None = None) -> int:
    """Runs the node until Ctrl-C (console script ``diagnosis_node``).

    Args:
        args: Command-line arguments (default ``sys.argv``), incl. ``--ros-args``.

    Returns:
        0, or 2 when the configuration is invalid (one line on stderr).
    """
    return run_node(
        DIAGNOSIS_SCHEMA.node,
        DiagnosisNode,
        lambda node: {MODEL_DISCREPANCY: node.published},
        args,
    )


if __name__ == '__main__':
    sys.exit(main())
