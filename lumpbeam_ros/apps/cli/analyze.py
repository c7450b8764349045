"""``lumpbeam analyze BAG``: a drop test, an arm move or any record's free vibrations.

See doc/interfaces.md.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from lumpbeam_ros.apps.cli.output import write_json
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.progress import Progress
from lumpbeam_ros.core.ident.bag_analysis import (
    CONTRACT_KEYS,
    POSE_TOPIC,
    BagAnalysis,
    analyze_bag,
    read_window,
    record_json,
    result_json,
)
from lumpbeam_ros.core.ident.settings import load_identifier_config, with_max_modes
from lumpbeam_ros.core.model.parameters import load_beam_config

if TYPE_CHECKING:
    from lumpbeam_ros.core.model.arm.config import ArmConfig

__all__ = ['CONTRACT_KEYS', 'Progress', 'read_window', 'result_json', 'run']


def run(args: argparse.Namespace) -> int:
    """Reads the bag, identifies the whole record, prints a summary, writes JSON and plots."""
    if args.fit_links and args.fit_payload:
        raise LumpbeamError('give --fit-links or --fit-payload, not both')
    if args.fit_links or args.fit_payload:
        from lumpbeam_ros.apps.cli.fit_links import run_fit_links, run_fit_payload

        return run_fit_links(args) if args.fit_links else run_fit_payload(args)
    if args.write_arm:
        raise LumpbeamError('--write-arm needs --fit-links or --fit-payload')
    if len(args.bag) > 1:
        raise LumpbeamError(
            f'{len(args.bag)} bags given: several bags only with --fit-links or --fit-payload'
        )
    args.bag = args.bag[0]
    beam, _ = load_beam_config(args.config)
    config = load_identifier_config(args.identifier_config)
    if args.max_modes is not None:
        config = with_max_modes(config, args.max_modes)
    arm = None
    if args.arm is not None:
        from lumpbeam_ros.core.model.arm.config import load_arm_config

        arm = load_arm_config(args.arm)
    band = None if args.band is None else parse_band(args.band)
    analysis = analyze_bag(
        args.bag, beam, config, arm_joints=None if arm is None else arm.n_joints, band=band
    )
    window, result = analysis.window, analysis.result
    for note in analysis.notes:
        print(f'lumpbeam analyze: warning: {args.bag}: {POSE_TOPIC}: {note}', file=sys.stderr)
    what = 'poses' if analysis.quantity == 'displacement' else 'accelerations (/tip_imu)'
    print(f'{args.bag}: {len(window)} {what} over {window.end_s - window.start_s:.2f} s')
    print(result.summary())
    _print_modes(analysis, arm)
    _print_record(analysis)
    if args.json:
        write_json(args.json, {**result_json(result, analysis.rest), **record_json(analysis)})
    if args.plots and analysis.quantity != 'displacement':
        raise LumpbeamError('--plots draws tip poses: the bag has accelerations (/tip_imu) only')
    if args.plots:
        from lumpbeam_ros.apps.plots.analysis import write_analysis_plots

        for path in write_analysis_plots(window, result, Path(args.plots)):
            print(f'wrote {path}')
    if args.report:
        from lumpbeam_ros.apps.report.analysis import write_analysis_report

        print(f'wrote {write_analysis_report(analysis, args.report)}')
    return 0 if result.ok else 1


def parse_band(text: str) -> tuple[float, float]:
    """``--band LOW,HIGH`` as ``(low, high)`` Hz.

    Raises:
        LumpbeamError: Not two numbers, or not ``0 <= LOW < HIGH``.
    """
    parts = text.split(',')
    try:
        low, high = (float(part) for part in parts)
    except ValueError:
        low = high = math.nan
    if not (math.isfinite(low) and math.isfinite(high) and 0.0 <= low < high):
        raise LumpbeamError(f'--band {text!r}: give LOW,HIGH in Hz with 0 <= LOW < HIGH')
    return low, high


def _print_record(analysis: BagAnalysis) -> None:
    """The free vibrations found and the steady lines, one line each."""
    unit = 'm' if analysis.quantity == 'displacement' else 'm/s^2'
    for event in analysis.events:
        modes = ', '.join(
            f'{m.natural_frequency_hz.value:.5g} Hz (zeta {m.damping_ratio.value:.3g})'
            for m in event.identification.modes
        )
        print(
            f'free vibration {event.event.start_s:.3f} to {event.event.end_s:.3f} s '
            f'({event.event.kind}): {modes or event.identification.message}'
        )
    for line in analysis.lines:
        print(f'steady line {line.frequency_hz:.5g} Hz, amplitude {line.amplitude:.3g} {unit}')


def _print_modes(analysis: BagAnalysis, arm: ArmConfig | None) -> None:
    """One line per mode; for an arm, the model's nearest mode at the rest angles beside it."""
    model: list[dict[str, float]] = []
    unit = 'm' if analysis.quantity == 'displacement' else 'm/s^2'
    rest = analysis.rest
    if rest is not None and arm is not None:
        import numpy as np

        from lumpbeam_ros.core.model.arm.model import ArmModel
        from lumpbeam_ros.core.model.arm.statics import arm_modes, modes_table

        angles = ', '.join(f'{q:.4g}' for q in rest.angles_rad)
        print(f'joints at rest from {rest.start_s:.3f} s at q = {angles} rad')
        model = modes_table(arm_modes(ArmModel.from_config(arm), np.array(rest.angles_rad)))
    for k, mode in enumerate(analysis.modes, start=1):
        f, zeta = mode.natural_frequency_hz, mode.damping_ratio
        line = (
            f'mode {k}: {f.value:.5g} +- {f.std:.2g} Hz, damping ratio {zeta.value:.4g} +- '
            f'{zeta.std:.2g}, amplitude {mode.amplitude_m:.3g} {unit}'
        )
        if model:
            near = min(model, key=lambda m: abs(m['natural_frequency_hz'] - f.value))
            line += (
                f' (arm model: {near["natural_frequency_hz"]:.5g} Hz, '
                f'damping ratio {near["damping_ratio"]:.4g})'
            )
        print(line)
