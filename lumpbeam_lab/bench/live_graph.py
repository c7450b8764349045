"""End-to-end latency of the live graph: camera frame stamp to ``/beam_params`` publication.

Three processes, as in the demo: a camera publisher offering frames stamped with the wall
clock (:mod:`lumpbeam_lab.bench.camera_stream`), the camera node tracking them into
``/tip_pose``, and the identifier node (on wall time) publishing ``/beam_params``. Each
``/beam_params`` message names the newest pose it used (``window_end_s``, the stamp of that
frame); its header stamp is when it was published. Their difference is the latency of the
whole chain, timed for the messages that bring a newer frame than the one before
(:class:`~lumpbeam_lab.bench.camera_stream.ParamsAges`: a repeated window only measures a
pause in the poses, such as the end of the stream). The baseline, measured in the same
run, is the first hop alone: frame stamp to the arrival of its ``/tip_pose`` at the bench
process. The ratio (baseline over value) is the part of the end-to-end latency that the
camera hop accounts for.
"""

from __future__ import annotations

import math

from lumpbeam_lab.bench import camera_stream
from lumpbeam_lab.bench.bench_result import BenchResult

#: How often the identifier publishes during the bench, Hz (more samples than the default).
PUBLISH_RATE_HZ = 10.0


def end_to_end(width: int, height: int, rate_hz: float, duration_s: float) -> BenchResult:
    """Measures frame stamp to ``/beam_params`` (value) and to ``/tip_pose`` (baseline).

    Args:
        width: Image width, px.
        height: Image height, px.
        rate_hz: Offered frame rate, Hz.
        duration_s: Publishing time, s.

    Returns:
        The p50 latencies, with p99 and counts in the details.

    Raises:
        RuntimeError: A process failed or discovery never completed.
    """
    figures = camera_stream.measure(
        camera_stream.camera_node_command(),
        width,
        height,
        rate_hz,
        duration_s,
        downstream=camera_stream.identifier_command(PUBLISH_RATE_HZ),
    )
    params = figures.params_latency_ms
    value = float(params.size and _percentile(params, 50))
    baseline = figures.percentile_ms(50)
    details = {
        'offered_fps': rate_hz,
        'frames_published': figures.published,
        'poses_received': figures.received,
        'beam_params_received': int(params.size) + figures.params_repeated,
        'beam_params_timed': int(params.size),
        'beam_params_latency_p50_ms': value if params.size else math.nan,
        'beam_params_latency_p99_ms': _percentile(params, 99),
        'tip_pose_latency_p50_ms': baseline,
        'tip_pose_latency_p99_ms': figures.percentile_ms(99),
    }
    if not params.size:
        value = math.nan
    return BenchResult(
        f'demo_e2e_latency_{width}x{height}',
        value,
        'ms (p50)',
        'frame stamp to /tip_pose arrival (p50)',
        baseline,
        baseline / value if value > 0 else math.nan,
        details,
    )


def _percentile(values: object, q: float) -> float:
    import numpy as np

    array = np.asarray(values, dtype=float)
    return float(np.percentile(array, q)) if array.size else math.nan


def run(quick: bool) -> list[BenchResult]:
    """Runs the suite.

    Args:
        quick: A smoke test: 3 s of 320 x 240 frames.

    Returns:
        One row: 640 x 480 at 180 fps for 10 s (quick: 320 x 240 for 3 s).
    """
    if quick:
        return [end_to_end(320, 240, 180.0, 3.0)]
    return [end_to_end(640, 480, 180.0, 10.0)]
