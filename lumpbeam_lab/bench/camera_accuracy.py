"""The camera's validation matrix (``lumpbeam bench --only camera-accuracy``).

Every row is a short drop test filmed by the independent ray caster
(:mod:`lumpbeam_lab.camera.raycast_camera`) and scored over every published pose: tip z
RMS with the bias in it against the 10 um target. The rows are printed as they finish, one
line each, then come back as results.
"""

from __future__ import annotations

import dataclasses

from lumpbeam_lab.bench.bench_result import BenchResult
from lumpbeam_lab.camera.accuracy import drop_test_trajectory
from lumpbeam_lab.camera.validation import (
    Z_RMS_LIMIT_UM,
    ValidationCase,
    format_row,
    matrix_cases,
    run_case,
)


def run(quick: bool) -> list[BenchResult]:
    """Runs the matrix.

    Args:
        quick: One 1024 x 1024 row, every 6th frame, calibrating on 10 frames.

    Returns:
        One result per row: z RMS, um, against the target.
    """
    cases: list[ValidationCase] = matrix_cases()
    if quick:
        cases = [dataclasses.replace(cases[1], frame_step=6, calibration_frames=10)]
    trajectory = drop_test_trajectory()
    results = []
    for i, case in enumerate(cases):
        report = run_case(case, trajectory)
        row = format_row(case, report)
        print(row, flush=True)
        z = report.z_um
        results.append(
            BenchResult(
                f'camera_accuracy_{case.size_px}_row{i}',
                z.rms,
                'um',
                'target 10 um',
                Z_RMS_LIMIT_UM,
                Z_RMS_LIMIT_UM / z.rms,
                {
                    'conditions': case.label(),
                    'frames': report.frames,
                    'frames_lost': report.frames_lost,
                    'z_bias_um': z.bias,
                    'z_std_um': z.std,
                    'z_p99_um': z.p99,
                    'z_max_um': z.max,
                    'x_rms_um': report.x_um.rms,
                    'pitch_rms_mrad': report.pitch_mrad.rms,
                    'within_1sigma': report.within_1sigma,
                },
            )  # fmt: skip
        )
    return results
