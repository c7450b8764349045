"""``lumpbeam shape IN OUT``: a joint trajectory convolved with an input shaper."""

from __future__ import annotations

import argparse

from lumpbeam_ros.apps.cli.output import write_json
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model.arm.joint_trajectory import read_trajectory_csv, write_trajectory_csv
from lumpbeam_ros.core.shaping.apply import shape_trajectory
from lumpbeam_ros.core.shaping.impulses import Mode
from lumpbeam_ros.core.shaping.modes_file import read_modes_json
from lumpbeam_ros.core.shaping.shapers import design_shaper
from lumpbeam_ros.core.shaping.vibration import vibration_summary


def modes_from_options(args: argparse.Namespace) -> list[Mode]:
    """The modes given by ``--frequency-hz``/``--damping-ratio`` or by ``--params``.

    Raises:
        LumpbeamError: Both ways or neither, a count of damping ratios that is neither 1 nor
            that of the frequencies, or a mode out of range.
    """
    frequencies = args.frequency_hz or []
    dampings = args.damping_ratio or []
    if args.params is not None:
        if frequencies or dampings:
            raise LumpbeamError('give the modes by --params or by --frequency-hz, not both')
        return read_modes_json(args.params)
    if not frequencies:
        if dampings:
            raise LumpbeamError('--damping-ratio needs --frequency-hz')
        raise LumpbeamError('give the modes: --frequency-hz F [--damping-ratio Z] or --params')
    if len(dampings) not in (0, 1, len(frequencies)):
        raise LumpbeamError(
            f'{len(frequencies)} --frequency-hz for {len(dampings)} --damping-ratio: give one '
            'damping ratio per frequency, or one for all'
        )
    dampings = (
        dampings if len(dampings) == len(frequencies) else (dampings or [0.0]) * len(frequencies)
    )
    modes = []
    for k, (f, z) in enumerate(zip(frequencies, dampings, strict=True), start=1):
        try:
            modes.append(Mode(f, z))
        except LumpbeamError as exc:
            raise LumpbeamError(f'mode {k} (--frequency-hz {f!r}): {exc}') from None
    return modes


def run(args: argparse.Namespace) -> int:
    """Designs the shaper, shapes the trajectory, writes it; prints what vibration is left."""
    modes = modes_from_options(args)
    impulses = design_shaper(args.shaper, modes)
    trajectory = read_trajectory_csv(args.input)
    shaped = shape_trajectory(trajectory, impulses)
    write_trajectory_csv(args.output, shaped)
    rate_hz = (shaped.time_s.size - 1) / shaped.duration_s
    print(
        f'{args.input}: {trajectory.joint_count} joints, {trajectory.time_s.size} samples over '
        f'{trajectory.duration_s:.3f} s'
    )
    print(
        f'{args.shaper.upper()} shaper for {len(modes)} mode(s): {impulses.time_s.size} '
        f'impulses, {impulses.duration_s:.4f} s added'
    )
    summaries = [vibration_summary(impulses, mode) for mode in modes]
    for k, s in enumerate(summaries, start=1):
        low, high = s['band_hz']
        print(
            f'  mode {k}: {s["natural_frequency_hz"]:.4g} Hz, damping ratio '
            f'{s["damping_ratio"]:.4g}: vibration left {100 * s["vibration_left"]:.2f} %, '
            f'{100 * s["vibration_left_15pct_low"]:.2f} % / '
            f'{100 * s["vibration_left_15pct_high"]:.2f} % at -/+15 %; '
            f'at most 5 % from {low:.4g} to {high:.4g} Hz'
        )
    print(f'wrote {args.output}: {shaped.time_s.size} samples at {rate_hz:.6g} Hz')
    if args.json:
        write_json(
            args.json,
            {
                'impulses': impulses.as_list(),
                'duration_added_s': impulses.duration_s,
                'shaper': args.shaper,
                'modes': summaries,
            },
        )
    return 0
