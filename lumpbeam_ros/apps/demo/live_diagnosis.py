"""What the diagnosis node did during the demo's replay, read back from the recording.

The node publishes ``/model_discrepancy`` (``lumpbeam/diagnosis``): its verdict on the
ring-down, and whether the simulator adopted the effects. The recording shows the rest: the
simulator's live gap (``/tip_pose`` against ``/tip_pose_predicted``) before the adoption and
after it.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from typing import Any

import numpy as np

from lumpbeam_ros.apps.demo.graph import ProcessGraph
from lumpbeam_ros.apps.demo.recording import RecordingAnalysis, prediction_lag
from lumpbeam_ros.apps.plots.demo import Residual
from lumpbeam_ros.base.interface import DIAGNOSIS_STATUS, MODEL_DISCREPANCY
from lumpbeam_ros.core.bagio import BagReader
from lumpbeam_ros.core.bagio.series import read_diagnostics

TOPIC = MODEL_DISCREPANCY
STATUS_NAME = DIAGNOSIS_STATUS
#: The live gap after an adoption starts this long after it: the prediction published in
#: the tick that applied it still carries the old model.
SETTLE_S = 0.2
#: A lag left after the adoption is worth a line from this much on, s.
TIMING_SHOWN_S = 0.001


def _settled(values: dict[str, str], message: str) -> bool:
    """Whether a status is a final word: a diagnosis whose adoption is decided, or a refusal."""
    if 'missing_effect' in values:
        return values.get('adoption', '') != 'asked'
    return message.startswith(('not diagnosed', 'diagnosis of'))


def wait_for_verdict(graph: ProcessGraph, timeout_s: float, watch: Sequence[str]) -> bool:
    """Waits until the diagnosis node has said its first verdict (and adopted or not).

    A diagnosis takes seconds of CPU; on a busy machine it may end after the replay, and the
    nodes must still be running for its adoption to reach the simulator and the recorder.

    Args:
        graph: The running graph (its domain).
        timeout_s: Longest wait, s.
        watch: Children that must keep running meanwhile.

    Returns:
        Whether the verdict came in time.

    Raises:
        LumpbeamError: A child of the graph exited meanwhile.
    """
    import rclpy
    from diagnostic_msgs.msg import DiagnosticArray
    from rclpy.context import Context
    from rclpy.executors import SingleThreadedExecutor
    from rclpy.node import Node

    context = Context()
    rclpy.init(context=context, domain_id=graph.domain_id)
    settled: list[bool] = []

    def on_status(msg: DiagnosticArray) -> None:
        for status in msg.status:
            values = {kv.key: kv.value for kv in status.values}
            if status.name == STATUS_NAME and _settled(values, status.message):
                settled.append(True)

    try:
        probe = Node('lumpbeam_demo_verdict', context=context)
        probe.create_subscription(DiagnosticArray, TOPIC, on_status, 10)
        executor = SingleThreadedExecutor(context=context)
        executor.add_node(probe)
        deadline = time.monotonic() + timeout_s
        while not settled and time.monotonic() < deadline:
            graph.check_running(watch)
            executor.spin_once(timeout_sec=0.1)
        executor.shutdown()
        probe.destroy_node()
    finally:
        rclpy.try_shutdown(context=context)
    return bool(settled)


def _number(values: dict[str, str], key: str) -> float:
    try:
        return float(values[key])
    except (KeyError, ValueError):
        return math.nan


def live_diagnosis(
    bag: Any, analysis: RecordingAnalysis, release_s: float
) -> dict[str, Any] | None:
    """The node's first diagnosis and adoption, and the live gap before and after it.

    Args:
        bag: The recording (with ``/model_discrepancy`` as the node published it).
        analysis: The recording's measured and predicted tip.
        release_s: The load change the diagnosis followed, s.

    Returns:
        ``missing_effect``, ``missing_effects``, ``parameters``, the diagnosis's own
        ``gap_before_rms_m``/``gap_after_rms_m``, ``adoption`` (what became of it),
        ``adopted_at_s`` and, for the spans ``before`` (release to adoption) and ``after``
        (adoption to the end), the live ``prediction_{span}_rms_m``, its
        ``prediction_{span}_relative`` to the swing, and the ``prediction_{span}_lag_s`` that
        aligns the prediction best there with the ``prediction_{span}_aligned_rms_m`` it
        leaves; ``None`` when the recording holds no diagnosis.
    """
    residual = analysis.residual
    if TOPIC not in BagReader(bag).topics:
        return None
    found: dict[str, Any] | None = None
    for stamp, statuses in read_diagnostics(bag, TOPIC):
        for status in statuses:
            values = dict(status.values)
            if status.name != STATUS_NAME or 'missing_effect' not in values:
                continue
            if found is None:
                names = values.get('missing_effects', '')
                found = {
                    'missing_effect': values['missing_effect'],
                    'missing_effects': [n for n in names.split(',') if n],
                    'message': status.message,
                    'level': status.level,
                    'gap_before_rms_m': _number(values, 'gap_before_rms_m'),
                    'gap_after_rms_m': _number(values, 'gap_after_rms_m'),
                    'window_s': [
                        _number(values, 'window_start_s'),
                        _number(values, 'window_end_s'),
                    ],
                    'adoption': values.get('adoption', ''),
                    'adopted_at_s': math.nan,
                }
            found['adoption'] = values.get('adoption', found['adoption'])
            if found['adoption'].startswith('adopted') and math.isnan(found['adopted_at_s']):
                found['adopted_at_s'] = stamp
    if found is None:
        return None
    adopted = found['adopted_at_s']
    if math.isfinite(adopted):
        spans = {'before': (release_s, adopted), 'after': (adopted + SETTLE_S, math.inf)}
        for name, (start, end) in spans.items():
            found[f'prediction_{name}_rms_m'] = residual.rms(start=start, end=end)
            found[f'prediction_{name}_relative'] = _relative(residual, start, end)
            # The latency adopted is the one the diagnosis node named, whose release it dated
            # by the poses sent around the unstamped /tip_load (a pose or so off): the lag in
            # each span separates that timing from the effect's own shift of the prediction.
            lag, aligned = prediction_lag(analysis.measured, analysis.predicted, start, end)
            found[f'prediction_{name}_lag_s'] = lag
            found[f'prediction_{name}_aligned_rms_m'] = aligned
    return found


def _relative(residual: Residual, start: float, end: float) -> float:
    """The RMS gap over a span as a fraction of the measured swing's RMS (its std) there.

    The swing decays while the gaps are compared, and a timing or latency error grows with
    the swing: the fraction compares spans of different amplitude fairly.
    """
    keep = (residual.t >= start) & (residual.t < end)
    if np.count_nonzero(keep) < 2:
        return math.nan
    return residual.rms(start=start, end=end) / float(np.std(residual.measured[keep]))


def live_diagnosis_lines(live: dict[str, Any]) -> list[str]:
    """The node's diagnosis for the summary: the effect named live, the gaps, the adoption."""
    start, end = live['window_s']
    names = ', '.join(live['missing_effects']) or live['missing_effect']
    lines = [
        f'live diagnosis (diagnosis_node, ring-down {start:.2f} to {end:.2f} s): {names}'
        f' - {live["message"]}',
        f'  its gap: RMS {live["gap_before_rms_m"] * 1e3:.3f} mm with the nominal model, '
        f'{live["gap_after_rms_m"] * 1e3:.3f} mm with the effect added',
        f'  adoption: {live["adoption"] or "-"}',
    ]
    after = live.get('prediction_after_rms_m', math.nan)
    if 'prediction_after_rms_m' in live and not math.isfinite(after):
        lines.append(
            f'  simulator live gap: RMS {live["prediction_before_rms_m"] * 1e3:.3f} mm from the '
            f'release on; the adoption at {live["adopted_at_s"]:.2f} s came after the replay '
            '(a longer --duration shows the gap after it)'
        )
    elif 'prediction_after_rms_m' in live:
        lines.append(
            f'  simulator live gap: RMS {live["prediction_before_rms_m"] * 1e3:.3f} mm '
            f'({live["prediction_before_relative"]:.1%} of the swing) from the release to the '
            f'adoption at {live["adopted_at_s"]:.2f} s, {after * 1e3:.3f} mm '
            f'({live["prediction_after_relative"]:.1%} of the swing) after it'
        )
        lag = live['prediction_after_lag_s']
        if math.isfinite(lag) and abs(lag) > TIMING_SHOWN_S:
            lines.append(
                f'  of which timing after it: the prediction runs {lag * 1e3:.1f} ms late '
                '(the latency named a pose or so off: the diagnosis dates the unstamped '
                '/tip_load by the poses sent around it); '
                f'{live["prediction_after_aligned_rms_m"] * 1e3:.3f} mm once aligned'
            )
    return lines
