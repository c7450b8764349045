"""``lumpbeam play BAG [--rate R] [--loop] [--topics ...]``: replay a bag with ``/clock``."""

from __future__ import annotations

import argparse
import signal
import sys
from typing import Any

from lumpbeam_ros.interface import CLOCK


def run(args: argparse.Namespace) -> int:
    """Plays the bag.

    Returns:
        0 after the bag played (or playback was stopped).

    Raises:
        BagError: The bag cannot be read, a topic is missing or its type is not installed.
    """
    import time

    import rclpy
    from rclpy.signals import SignalHandlerOptions

    from lumpbeam_ros.bagio import BagReader
    from lumpbeam_ros.nodes.player import Player

    reader = BagReader(args.bag)
    stopped = {'signal': None}

    def request_stop(signum: int, _frame: Any) -> None:
        stopped['signal'] = signum

    previous = {s: signal.signal(s, request_stop) for s in (signal.SIGINT, signal.SIGTERM)}
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    player = None
    try:
        player = Player(reader, args.topics, rate=args.rate)
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
            stats = player.play(lambda: stopped['signal'] is not None)
            passes += 1
            if not args.loop or stopped['signal'] is not None:
                break
    finally:
        if player is not None:
            player.destroy_node()
        rclpy.try_shutdown()
        for sig, handler in previous.items():
            signal.signal(sig, handler)
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
