"""``lumpbeam modes --arm FILE --q=Q1,...,QN``: an arm's modes at given joint angles."""

from __future__ import annotations

import argparse
import math

import numpy as np

from lumpbeam_ros.apps.cli.output import write_json
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model.arm.config import load_arm_config
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.statics import arm_modes, modes_table


def parse_angles(text: str, count: int) -> np.ndarray:
    """``--q``: ``count`` comma-separated finite numbers (rad).

    Raises:
        LumpbeamError: A value that is not a finite number, or the wrong count.
    """
    values = []
    for part in text.split(','):
        try:
            value = float(part)
        except ValueError:
            raise LumpbeamError(f'--q {text!r}: {part.strip()!r} is not a number') from None
        if not math.isfinite(value):
            raise LumpbeamError(f'--q {text!r}: angles must be finite')
        values.append(value)
    if len(values) != count:
        raise LumpbeamError(
            f'--q {text!r}: the arm has {count} joint(s), got {len(values)} angle(s)'
        )
    return np.array(values)


def run(args: argparse.Namespace) -> int:
    """Computes and prints the modes; writes them as JSON with ``--json``."""
    config = load_arm_config(args.arm)
    if args.payload_kg is not None:
        config = config.with_payload(args.payload_kg)
    q = parse_angles(args.q, config.n_joints)
    table = modes_table(arm_modes(ArmModel.from_config(config), q))
    segments = sum(link.n_segments for link in config.links)
    print(
        f'{args.arm}: {config.n_joints} link(s), {segments} segments, {config.plane} plane, '
        f'payload {config.payload_kg:g} kg, q = {", ".join(f"{v:g}" for v in q)} rad: '
        f'{len(table)} underdamped mode(s)'
    )
    for k, mode in enumerate(table[:10], start=1):
        print(
            f'  mode {k}: {mode["natural_frequency_hz"]:.4f} Hz, damping ratio '
            f'{mode["damping_ratio"]:.4g}'
        )
    if len(table) > 10:
        print(f'  ... {len(table) - 10} more (--json lists them all)')
    if args.json:
        write_json(
            args.json,
            {
                'modes': table,
                'joint_angles_rad': q.tolist(),
                'payload_kg': config.payload_kg,
                'plane': config.plane,
            },
        )
    return 0
