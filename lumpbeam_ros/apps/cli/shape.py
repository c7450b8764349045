"""``lumpbeam shape IN OUT``: a joint trajectory convolved with an input shaper.

With ``--arm FILE``, each move is shaped for the modes of the arm's model at its own final
angles (and with ``--tune``, on the model's simulation of it).
"""

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
    if args.arm is not None:
        return run_by_model(args)
    given = [
        option
        for option, value in (
            ('--payload-kg', args.payload_kg),
            ('--max-modes', args.max_modes),
            ('--tune', args.tune or None),
        )
        if value is not None
    ]
    if given:
        raise LumpbeamError(f'{", ".join(given)}: only with --arm FILE')
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


def run_by_model(args: argparse.Namespace) -> int:
    """Shapes each move for the arm model's modes at its end; prints a line per move.

    Raises:
        LumpbeamError: Modes given as well, a bad arm file or trajectory, a trajectory for
            another number of joints or outside a joint's limits.
    """
    from lumpbeam_ros.core.model.arm.config import load_arm_config
    from lumpbeam_ros.core.shaping.choices import DEFAULT_MAX_MODES
    from lumpbeam_ros.core.shaping.workspace import WorkspaceShaper

    if args.frequency_hz or args.damping_ratio or args.params is not None:
        raise LumpbeamError(
            '--arm shapes each move for the modes of the model: not with --frequency-hz, '
            '--damping-ratio or --params'
        )
    arm = load_arm_config(args.arm)
    if args.payload_kg is not None:
        arm = arm.with_payload(args.payload_kg)
    trajectory = read_trajectory_csv(args.input)
    max_modes = DEFAULT_MAX_MODES if args.max_modes is None else args.max_modes
    shaper = WorkspaceShaper(arm, args.shaper, max_modes, tune=args.tune)
    shaped, moves = shaper.shape(trajectory)
    write_trajectory_csv(args.output, shaped)
    print(
        f'{args.input}: {trajectory.joint_count} joints, {len(moves)} move(s) over '
        f'{trajectory.duration_s:.3f} s; {args.shaper.upper()} for the first {max_modes} '
        f"mode(s) of {args.arm} at each move's end{', tuned' if args.tune else ''}"
    )
    for k, move in enumerate(moves, start=1):
        modes = ', '.join(f'{m.frequency_hz:.4g} Hz' for m in move.modes)
        print(
            f'  move {k}: {move.start_s:.3f}-{move.end_s:.3f} s, modes {modes}: '
            f'{move.impulses.time_s.size} impulses, {move.impulses.duration_s:.4f} s added; '
            f'predicted residual {1e3 * move.predicted_residual_unshaped_m:.4g} mm unshaped, '
            f'{1e3 * move.predicted_residual_shaped_m:.4g} mm shaped '
            f'({100 * move.reduction:.2f} % less)'
        )
    print(f'wrote {args.output}: {shaped.time_s.size} samples over {shaped.duration_s:.3f} s')
    if args.json:
        write_json(
            args.json,
            {
                'moves': [move.as_json() for move in moves],
                'duration_added_s': sum(move.impulses.duration_s for move in moves),
                'shaper': args.shaper,
                'tuned': args.tune,
            },
        )
    return 0
