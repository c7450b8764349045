"""``lumpbeam play BAG [--rate R] [--loop] [--topics ...] [--namespace NS]``: replay a bag."""

from __future__ import annotations

import argparse
import sys

from lumpbeam_ros.base.interface import CLOCK


def run(args: argparse.Namespace) -> int:
    """Plays the bag.

    Returns:
        0 after the bag played (or playback was stopped).

    Raises:
        LumpbeamError: rclpy rejects the namespace.
        BagError: The bag cannot be read, a topic is missing or its type is not installed.
    """
    import time

    from lumpbeam_ros.core.bagio import BagReader
    from lumpbeam_ros.nodes.lifecycle import checked_namespace, stoppable_session
    from lumpbeam_ros.nodes.player import MAX_GAP_S, Player, PlayStats, sleep_until

    namespace = checked_namespace(args.namespace)
    reader = BagReader(args.bag)
    with stoppable_session() as stop:
        player = None
        try:
            player = Player(reader, args.topics, rate=args.rate, namespace=namespace)
            sleep_until(time.perf_counter() + args.delay, lambda: stop.requested)
            # A message sent before a reliable subscriber is matched is not delivered to it.
            unheard = player.wait_for_subscribers(args.delay, lambda: stop.requested)
            if unheard and not stop.requested:
                print(
                    f'lumpbeam play: warning: no subscriber yet on {", ".join(unheard)}',
                    file=sys.stderr,
                )
            passes = 0
            stats = PlayStats({})
            while not stop.requested:
                stats = player.play(lambda: stop.requested)
                passes += 1
                if stats.gaps_shortened:
                    print(
                        f'lumpbeam play: warning: {stats.gaps_shortened} gap'
                        f'{"s" if stats.gaps_shortened > 1 else ""} between messages longer '
                        f'than {MAX_GAP_S:g} s played as {MAX_GAP_S:g} s (longest '
                        f'{stats.longest_gap_s:g} s of bag time); /clock jumps as the bag does',
                        file=sys.stderr,
                    )
                if not args.loop:
                    break
        finally:
            if player is not None:
                player.destroy_node()
    from lumpbeam_ros.nodes.counts import write_counts

    write_counts('player', {**stats.published, CLOCK: stats.clock_published})
    total = sum(stats.published.values())
    print(
        f'played {args.bag} ({passes} pass{"" if passes == 1 else "es"}): {total} messages in '
        f'the last pass, lateness p99 {stats.lateness_percentile_ms(99):.2f} ms'
    )
    if not stats.delivered:
        print(
            'lumpbeam play: warning: reliable subscribers did not acknowledge every message '
            'before the end',
            file=sys.stderr,
        )
    return 0
