"""``lumpbeam play BAG [--rate R] [--loop] [--topics ...] [--namespace NS]``: replay a bag."""

from __future__ import annotations

import argparse
import sys

from lumpbeam_ros.interface import CLOCK


def run(args: argparse.Namespace) -> int:
    """Plays the bag.

    Returns:
        0 after the bag played (or playback was stopped).

    Raises:
        LumpbeamError: rclpy rejects the namespace.
        BagError: The bag cannot be read, a topic is missing or its type is not installed.
    """
    import time

    from lumpbeam_ros.bagio import BagReader
    from lumpbeam_ros.nodes.lifecycle import checked_namespace, stoppable_session
    from lumpbeam_ros.nodes.player import Player

    namespace = checked_namespace(args.namespace)
    reader = BagReader(args.bag)
    with stoppable_session() as stop:
        player = None
        try:
            player = Player(reader, args.topics, rate=args.rate, namespace=namespace)
            time.sleep(args.delay)
            # A message sent before a reliable subscriber is matched is not delivered to it.
            unheard = player.wait_for_subscribers(args.delay)
            if unheard:
                print(
                    f'lumpbeam play: warning: no subscriber yet on {", ".join(unheard)}',
                    file=sys.stderr,
                )
            passes = 0
            while True:
                stats = player.play(lambda: stop.requested)
                passes += 1
                if not args.loop or stop.requested:
                    break
        finally:
            if player is not None:
                player.destroy_node()
    from lumpbeam_ros.nodes.counts import write_counts

    write_counts('player', {**stats.published, CLOCK: stats.clock_published})
    total = sum(stats.published.values())
    print(
        f'played {args.bag} ({passes} pass{"es" if passes > 1 else ""}): {total} messages in '
        f'the last pass, lateness p99 {stats.lateness_percentile_ms(99):.2f} ms'
    )
    if not stats.delivered:
        print(
            'lumpbeam play: warning: reliable subscribers did not acknowledge every message '
            'before the end',
            file=sys.stderr,
        )
    return 0
