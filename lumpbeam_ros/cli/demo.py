"""``lumpbeam demo [--out DIR]``: the whole pipeline on the built-in synthetic experiment."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from lumpbeam_ros.cli.output import positive_float, write_json


def register(subparsers: Any) -> None:
    """Adds the ``demo`` subcommand."""
    parser = subparsers.add_parser(
        'demo',
        help='the whole pipeline on the built-in synthetic experiment',
        description='Synthesizes a drop test, replays it through the live node graph '
        '(player, simulator, identifier, recorder as separate processes on a private ROS '
        'domain), analyzes the recording and draws measured against predicted.',
    )
    parser.add_argument('--out', type=Path, default=Path('results'), help='output folder')
    parser.add_argument(
        '--duration', type=positive_float, default=12.0, help='record length, s (default 12)'
    )
    parser.add_argument('--seed', type=int, default=0, help='seed of the pose noise')
    parser.add_argument(
        '--adopt', action='store_true', help='the simulator adopts the live identified values'
    )
    parser.add_argument('--domain-id', type=int, help='ROS domain (default: a random one)')
    parser.add_argument('--config', type=Path, help='beam parameter file')
    parser.add_argument('--json', type=Path, help='also write the summary here')
    parser.add_argument(
        '--image-size',
        default='640x480',
        metavar='WxH',
        help='synthetic camera frames, tracked by the camera node (default 640x480)',
    )
    parser.add_argument(
        '--no-images', action='store_true', help="play the bag's /tip_pose, no camera node"
    )
    parser.add_argument(
        '--effect',
        action='append',
        metavar='NAME=VALUE',
        help='effect hidden in the data for the diagnosis (repeatable; default '
        'sensor_latency=0.015); --effect none hides nothing',
    )
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    """Runs the demo.

    Returns:
        0 when every step ran.

    Raises:
        LumpbeamError: A bad option or a failed step (one line, see the logs it names).
    """
    from lumpbeam_ros.errors import LumpbeamError
    from lumpbeam_ros.pipeline.demo import DemoOptions, run_demo
    from lumpbeam_ros.pipeline.graph import DOMAIN_IDS

    if args.domain_id is not None and args.domain_id not in DOMAIN_IDS:
        raise LumpbeamError(
            f'--domain-id must be in {DOMAIN_IDS.start}..{DOMAIN_IDS.stop - 1}, '
            f'got {args.domain_id}'
        )
    if args.out.exists() and not args.out.is_dir():
        raise LumpbeamError(f'--out {args.out} is a file, not a folder')
    from lumpbeam_ros.pipeline.demo import HIDDEN_EFFECT
    from lumpbeam_ros.synthetic.drop_test import parse_effect
    from lumpbeam_ros.synthetic.images import parse_image_size

    if args.effect is None:
        effects = dict(HIDDEN_EFFECT)
    elif args.effect == ['none']:
        effects = {}
    else:
        effects = dict(parse_effect(text) for text in args.effect)
    size = None if args.no_images else parse_image_size(args.image_size)
    options = DemoOptions(
        out=args.out,
        duration_s=args.duration,
        seed=args.seed,
        adopt_identified=args.adopt,
        domain_id=args.domain_id,
        beam_config=args.config,
        image_size=size,
        effects=effects,
    )
    result = run_demo(options, echo=lambda line: print(line, flush=True))
    if args.json is not None:
        write_json(args.json, result.summary)
    return 0
