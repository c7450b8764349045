"""``lumpbeam synth OUT``: a synthetic drop-test bag (SPEC section 5)."""

from __future__ import annotations

import argparse

from lumpbeam_ros.cli.output import non_negative_float, positive_float
from lumpbeam_ros.errors import LumpbeamError
from lumpbeam_ros.model.parameters import BeamParameters, DropTestConfig, load_beam_config
from lumpbeam_ros.synthetic.drop_test import SynthOptions, parse_effect, write_drop_test_bag
from lumpbeam_ros.synthetic.images import ImageOptions, parse_image_size
from lumpbeam_ros.synthetic.tracker import TrackerOptions


def register(subparsers: argparse._SubParsersAction) -> None:
    """Adds the ``synth`` subcommand."""
    parser = subparsers.add_parser('synth', help='write a synthetic drop-test bag')
    parser.add_argument('out', help='bag folder to create (must not exist)')
    parser.add_argument(
        '--loads',
        metavar='KG,KG,...',
        help='write a campaign: OUT becomes a folder of bags, one per load and seed',
    )
    parser.add_argument(
        '--seeds', type=int, default=1, metavar='N', help='with --loads: bags per load (1)'
    )
    parser.add_argument('--config', help='beam parameter file (default: config/paper_beam.yaml)')
    parser.add_argument('--duration', type=positive_float, default=12.0, help='seconds (12)')
    parser.add_argument('--rate', type=positive_float, default=180.0, help='pose rate, Hz (180)')
    parser.add_argument(
        '--noise', type=non_negative_float, default=20e-6, help='pose noise sigma, m (20e-6)'
    )
    parser.add_argument('--seed', type=int, default=0, help='noise seed (0)')
    parser.add_argument(
        '--effect',
        action='append',
        default=[],
        metavar='NAME=VALUE',
        help='hide a physical effect of SPEC section 6 in the data (repeatable)',
    )
    tracker = parser.add_argument_group('reference sensor (/tracker/point)')
    tracker.add_argument(
        '--tracker', action='store_true', help='add a simulated laser tracker at the tip'
    )
    defaults = TrackerOptions()
    tracker.add_argument(
        '--tracker-rate', type=positive_float, default=defaults.rate_hz, help='Hz (1000)'
    )
    tracker.add_argument(
        '--tracker-noise',
        type=non_negative_float,
        default=defaults.noise_m,
        help='noise sigma per axis, m (15e-6)',
    )
    tracker.add_argument(
        '--tracker-offset',
        type=float,
        default=defaults.clock_offset_s,
        help='tracker clock minus true time, s (7.3e-3)',
    )
    tracker.add_argument(
        '--tracker-pose',
        type=_tracker_pose,
        default=(*defaults.position_m, *defaults.rotation_deg),
        metavar='X,Y,Z,ROLL,PITCH,YAW',
        help='tracker frame in beam_base: m and extrinsic xyz degrees (1.2,-3,0.35,4,-8,100)',
    )
    tracker.add_argument(
        '--tracker-lever', type=float, default=0.0, help='reflector beyond the tip, m (0)'
    )
    parser.add_argument(
        '--images',
        action='store_true',
        help='also film the tip camera: /camera/image_raw (mono8) and /camera/camera_info',
    )
    parser.add_argument(
        '--image-size',
        default='2048x2048',
        metavar='WxH',
        help='image size with --images (2048x2048: 4 MB a frame, 8.6 GB for 12 s)',
    )
    parser.add_argument('--camera-config', help='camera file (default: config/camera.yaml)')
    parser.set_defaults(handler=run)


def _tracker_pose(text: str) -> tuple[float, ...]:
    try:
        values = tuple(float(v) for v in text.split(','))
    except ValueError:
        raise argparse.ArgumentTypeError(f'expected 6 numbers, got {text!r}') from None
    if len(values) != 6:
        raise argparse.ArgumentTypeError(f'expected 6 comma-separated numbers, got {text!r}')
    return values


def _tracker_options(args: argparse.Namespace) -> TrackerOptions | None:
    if not args.tracker:
        return None
    pose = args.tracker_pose
    return TrackerOptions(
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
    effects = dict(parse_effect(text) for text in args.effect)
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
    tracker = _tracker_options(args)
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
    from lumpbeam_ros.synthetic.campaign import parse_loads, write_campaign

    if args.tracker or args.images:
        raise LumpbeamError('--loads writes pose-only bags: drop --tracker and --images')
    loads = parse_loads(args.loads)
    bags = write_campaign(args.out, beam, drop, options, loads, args.seeds)
    print(
        f'wrote {len(bags)} bags into {args.out}: loads {", ".join(f"{x:g}" for x in loads)} kg '
        f'x {args.seeds} seeds from {args.seed}, {args.duration:g} s each'
    )
    return 0
