"""``lumpbeam doctor BAG [BAG ...]``: the checks of ``mcap doctor`` on rosbag2 folders."""

from __future__ import annotations

import argparse

#: Exit code when a bag has a problem (a usage error stays 2).
PROBLEMS_FOUND = 1


def run(args: argparse.Namespace) -> int:
    """Examines each bag and prints its problems, or that it is clean.

    Returns:
        0 when every bag is clean, :data:`PROBLEMS_FOUND` otherwise.

    Raises:
        BagError: A folder that is not a bag, or a file that cannot be opened.
    """
    from lumpbeam_ros.core.bagio.check import examine_bag

    unclean = 0
    for bag in args.bags:
        problems = examine_bag(bag)
        for line in problems:
            print(f'{bag}: {line}')
        if problems:
            unclean += 1
        else:
            print(f'{bag}: clean')
    return PROBLEMS_FOUND if unclean else 0
