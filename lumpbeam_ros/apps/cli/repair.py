"""``lumpbeam repair BAG [OUT]``: a damaged or cut bag made whole for every reader."""

from __future__ import annotations

import argparse


def run(args: argparse.Namespace) -> int:
    """Repairs the bag and prints what was kept.

    Returns:
        0 when the copy was written.

    Raises:
        BagError: The bag cannot be opened, OUT exists, or a write fails.
    """
    from lumpbeam_ros.core.bagio.repair import repair_bag

    summary = repair_bag(args.bag, args.out)
    kept = sum(summary.kept.values())
    per_topic = ', '.join(f'{t} {n}' for t, n in sorted(summary.kept.items())) or 'nothing'
    print(f'repaired {args.bag} into {summary.out}: {kept} messages ({per_topic})')
    for topic, listed in sorted(summary.listed.items()):
        if summary.kept.get(topic, 0) < listed:
            print(
                f'warning: {topic}: kept {summary.kept.get(topic, 0)} of the {listed} messages '
                'the damaged metadata listed'
            )
    return 0
