"""``lumpbeam synth OUT``: a synthetic drop-test bag (doc/interfaces.md, 'Command line')."""

from __future__ import annotations

import argparse

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.bagio.writer import replace_bags
from lumpbeam_ros.core.model.parameters import BeamParameters, DropTestConfig, load_beam_config
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, parse_effects, write_drop_test_bag
from lumpbeam_ros.core.synthetic.images import ImageOptions, parse_image_size
from lumpbeam_ros.core.synthetic.reference_sensor import ReferenceSensorOptions


def _reference_sensor_options(args: argparse.Namespace) -> ReferenceSensorOptions | None:
    if not args.tracker:
        return None
    pose = args.tracker_pose
    return ReferenceSensorOptions(
        rate_hz=args.tracker_rate,
        noise_m=args.tracker_noise,
        clock_offset_s=args.tracker_offset,
        position_m=pose[:3],
        rotation_deg=pose[3:],
        lever_m=args.tracker_lever,
        seed=args.seed + 1,
    )


def run(args: argparse.Namespace) -> int:
    """Simulates and writes the bag, then prints what it holds."""
    if args.force:
        replace_bags(args.out)
    if args.arm is not None or args.trajectory is not None:
        return _write_arm(args)
    effects = parse_effects(args.effect)
    beam, drop = load_beam_config(args.config)
    options = SynthOptions(
        duration_s=args.duration,
        rate_hz=args.rate,
        noise_m=args.noise,
        seed=args.seed,
        effects=effects,
    )
    if args.loads is not None:
        return _write_campaign(args, beam, drop, options)
    tracker = _reference_sensor_options(args)
    images = None
    if args.images:
        width, height = parse_image_size(args.image_size)
        images = ImageOptions(width, height, args.camera_config, args.seed)
    measured, _ = write_drop_test_bag(
        args.out, beam, drop, options, tracker=tracker, images=images
    )
    hidden = ', '.join(f'{k}={v:g}' for k, v in effects.items()) or 'none'
    print(
        f'wrote {args.out}: {len(measured)} poses at {args.rate:g} Hz over {args.duration:g} s, '
        f'{drop.load_kg:g} kg released at {drop.release_time_s:g} s, '
        f'noise {args.noise * 1e6:g} um, hidden effects: {hidden}'
    )
    if tracker is not None:
        print(
            f'  with /tracker/point at {tracker.rate_hz:g} Hz in frame {tracker.frame_id!r}, '
            f'noise {tracker.noise_m * 1e6:g} um, clock offset {tracker.clock_offset_s:g} s'
        )
    if images is not None:
        print(f'  + {len(measured)} mono8 frames of {images.width}x{images.height} px')
    return 0


def _write_campaign(
    args: argparse.Namespace, beam: BeamParameters, drop: DropTestConfig, options: SynthOptions
) -> int:
    """``--loads``: a folder of drop-test bags, one per load and seed."""
    from lumpbeam_ros.core.synthetic.campaign_bags import parse_loads, write_campaign

    if args.tracker or args.images:
        raise LumpbeamError('--loads writes pose-only bags: drop --tracker and --images')
    loads = parse_loads(args.loads)
    bags = write_campaign(args.out, beam, drop, options, loads, args.seeds)
    print(
        f'wrote {len(bags)} bags into {args.out}: loads {", ".join(f"{x:g}" for x in loads)} kg '
        f'x {args.seeds} seeds from {args.seed}, {args.duration:g} s each'
    )
    return 0


def _write_arm(args: argparse.Namespace) -> int:
    """``--arm FILE --trajectory FILE``: the arm moved along the trajectory."""
    from lumpbeam_ros.core.model.arm.config import load_arm_config
    from lumpbeam_ros.core.model.arm.joint_trajectory import read_trajectory_csv
    from lumpbeam_ros.core.synthetic.arm_bag import CAMERA_FILE, ArmSynthOptions, write_arm_bag

    if args.arm is None or args.trajectory is None:
        raise LumpbeamError('--arm and --trajectory go together')
    beam_only = [
        name
        for name, given in (
            ('--loads', args.loads is not None),
            ('--config', args.config is not None),
            ('--effect', bool(args.effect)),
            ('--tracker', args.tracker),
        )
        if given
    ]
    if beam_only:
        raise LumpbeamError(f'{", ".join(beam_only)}: not for an arm (--arm)')
    config = load_arm_config(args.arm)
    trajectory = read_trajectory_csv(args.trajectory)
    options = ArmSynthOptions(
        duration_s=args.duration, rate_hz=args.rate, noise_m=args.noise, seed=args.seed
    )
    images = None
    if args.images:
        width, height = parse_image_size(args.image_size)
        images = ImageOptions(width, height, args.camera_config, args.seed)
    motion = write_arm_bag(args.out, config, trajectory, options, images)
    print(
        f'wrote {args.out}: {config.n_joints}-link arm along {args.trajectory} '
        f'({trajectory.duration_s:g} s), {motion.t.size} poses and joint states at '
        f'{args.rate:g} Hz over {args.duration:g} s, noise {args.noise * 1e6:g} um'
    )
    if images is not None:
        print(
            f'  + {motion.t.size} mono8 frames of {images.width}x{images.height} px from the tip '
            f'camera; the board faces it at rest after the move: track with '
            f'--config {args.out}/{CAMERA_FILE}'
        )
    return 0
