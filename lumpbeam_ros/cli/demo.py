"""``lumpbeam demo [--out DIR]``: the whole pipeline on the built-in synthetic experiment."""

from __future__ import annotations

import argparse

from lumpbeam_ros.cli.output import write_json


def run(args: argparse.Namespace) -> int:
    """Runs the demo.

    Returns:
        0 when every step ran.

    Raises:
        LumpbeamError: A bad option or a failed step (one line, see the logs it names).
    """
    from lumpbeam_ros.demo.graph import DOMAIN_IDS
    from lumpbeam_ros.demo.steps import DemoOptions, run_demo
    from lumpbeam_ros.errors import LumpbeamError

    if args.domain_id is not None and args.domain_id not in DOMAIN_IDS:
        raise LumpbeamError(
            f'--domain-id must be in {DOMAIN_IDS.start}..{DOMAIN_IDS.stop - 1}, '
            f'got {args.domain_id}'
        )
    if args.out.exists() and not args.out.is_dir():
        raise LumpbeamError(f'--out {args.out} is a file, not a folder')
    from lumpbeam_ros.demo.steps import HIDDEN_EFFECT
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
