"""``lumpbeam demo [--out DIR] [--arm [FILE]] [--workspace]``: the built-in experiments.

Without ``--arm`` the synthetic drop test; with it the input-shaping loop on an arm; with
``--workspace`` the arm learned live and shaped across its workspace.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from lumpbeam_ros.apps.cli.output import write_json


def run(args: argparse.Namespace) -> int:
    """Runs the demo.

    Returns:
        0 when every step ran.

    Raises:
        LumpbeamError: A bad option or a failed step (one line, see the logs it names).
    """
    from lumpbeam_ros.apps.demo.graph import DOMAIN_IDS
    from lumpbeam_ros.apps.demo.run import DemoOptions
    from lumpbeam_ros.apps.demo.steps import run_demo
    from lumpbeam_ros.base.errors import LumpbeamError

    if args.domain_id is not None and args.domain_id not in DOMAIN_IDS:
        raise LumpbeamError(
            f'--domain-id must be in {DOMAIN_IDS.start}..{DOMAIN_IDS.stop - 1}, '
            f'got {args.domain_id}'
        )
    args.out = output_folder(args.out, args.arm is not None, args.workspace)
    if args.out.exists() and not args.out.is_dir():
        raise LumpbeamError(f'--out {args.out} is a file, not a folder')
    if args.arm is not None or args.workspace:
        return _run_arm(args)
    from lumpbeam_ros.apps.demo.run import HIDDEN_EFFECT
    from lumpbeam_ros.core.synthetic.drop_test import parse_effects
    from lumpbeam_ros.core.synthetic.images import parse_image_size

    effects = dict(HIDDEN_EFFECT) if args.effect is None else parse_effects(args.effect)
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


#: Where the demos write when ``--out`` is not given: no two share a folder.
DEFAULT_OUT = Path('results')
ARM_OUT = DEFAULT_OUT / 'arm'
WORKSPACE_OUT = DEFAULT_OUT / 'workspace'


def output_folder(out: Path | None, arm: bool, workspace: bool = False) -> Path:
    """``--out``, or the demo's own folder under ``results/`` (``arm``, ``workspace``)."""
    if out is not None:
        return out
    if workspace:
        return WORKSPACE_OUT
    return ARM_OUT if arm else DEFAULT_OUT


#: The options of the drop test that the arm demo has no use for, with their defaults.
BEAM_ONLY = {
    'duration': 12.0,
    'seed': 0,
    'adopt': False,
    'config': None,
    'effect': None,
    'image_size': '640x480',
    'no_images': False,
}


def _run_arm(args: argparse.Namespace) -> int:
    """Runs an arm demo (``--arm``, ``--workspace``); refuses the drop test's options."""
    from lumpbeam_ros.base.errors import LumpbeamError
    from lumpbeam_ros.base.resources import config_path

    given = [name for name, default in BEAM_ONLY.items() if getattr(args, name) != default]
    if given:
        option = '--' + given[0].replace('_', '-')
        which = '--workspace' if args.workspace else '--arm'
        raise LumpbeamError(f'{option} is an option of the drop-test demo, not of {which}')
    echo = lambda line: print(line, flush=True)  # noqa: E731
    summary: dict[str, Any]
    if args.workspace:
        from lumpbeam_ros.apps.demo.workspace_loop import (
            WorkspaceDemoOptions,
            run_workspace_demo,
        )

        arm = Path(args.arm) if args.arm else config_path('arm_2link.yaml')
        options = WorkspaceDemoOptions(arm_config=arm, out=args.out, domain_id=args.domain_id)
        summary = run_workspace_demo(options, echo=echo).summary
    else:
        from lumpbeam_ros.apps.demo.arm_loop import ArmDemoOptions, run_arm_demo

        arm = Path(args.arm) if args.arm else config_path('arm_rotary.yaml')
        arm_options = ArmDemoOptions(arm_config=arm, out=args.out, domain_id=args.domain_id)
        summary = run_arm_demo(arm_options, echo=echo).summary
    if args.json is not None:
        write_json(args.json, summary)
    return 0
