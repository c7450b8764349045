"""``lumpbeam synth OUT``: a synthetic drop-test bag (SPEC section 5)."""

from __future__ import annotations

import argparse

from lumpbeam_ros.cli.output import non_negative_float, positive_float
from lumpbeam_ros.model.parameters import load_beam_config
from lumpbeam_ros.synthetic.drop_test import SynthOptions, parse_effect, write_drop_test_bag
from lumpbeam_ros.synthetic.images import ImageOptions, parse_image_size


def register(subparsers: argparse._SubParsersAction) -> None:
    """Adds the ``synth`` subcommand."""
    parser = subparsers.add_parser('synth', help='write a synthetic drop-test bag')
    parser.add_argument('out', help='bag folder to create (must not exist)')
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
    images = None
    if args.images:
        width, height = parse_image_size(args.image_size)
        images = ImageOptions(width, height, args.camera_config, args.seed)
    measured, _ = write_drop_test_bag(args.out, beam, drop, options, images)
    hidden = ', '.join(f'{k}={v:g}' for k, v in effects.items()) or 'none'
    print(
        f'wrote {args.out}: {len(measured)} poses at {args.rate:g} Hz over {args.duration:g} s, '
        f'{drop.load_kg:g} kg released at {drop.release_time_s:g} s, '
        f'noise {args.noise * 1e6:g} um, hidden effects: {hidden}'
    )
    if images is not None:
        print(f'  + {len(measured)} mono8 frames of {images.width}x{images.height} px')
    return 0
