"""``lumpbeam record OUT [TOPIC...] [--all] [--namespace NS]``: record live topics into a bag."""

from __future__ import annotations

import argparse
import time
from typing import Any

from lumpbeam_ros.base.errors import LumpbeamError


def run(args: argparse.Namespace) -> int:
    """Records until stopped.

    Returns:
        0 after a clean stop.

    Raises:
        LumpbeamError: No topic given, a topic name or namespace rclpy rejects, an existing
            OUT, or a write error.
    """
    if not args.topics and not args.all:
        raise LumpbeamError('name the topics to record, or pass --all')
    if args.topics and args.all:
        raise LumpbeamError('give either topics or --all, not both')
    # Imported here so that `lumpbeam --help` and the ROS-free commands never load rclpy.
    from rclpy.executors import SingleThreadedExecutor

    from lumpbeam_ros.core.bagio import BagWriter
    from lumpbeam_ros.nodes.lifecycle import checked_namespace, checked_topics, stoppable_session
    from lumpbeam_ros.nodes.recorder import Recorder

    namespace = checked_namespace(args.namespace)
    topics = checked_topics(args.topics)
    bag = BagWriter(args.out, flush_period_s=args.flush_period)
    with stoppable_session() as stop:
        node = None
        try:
            node = Recorder(
                bag,
                None if args.all else topics,
                flush_period_s=args.flush_period,
                namespace=namespace,
            )
            executor = SingleThreadedExecutor()
            executor.add_node(node)
            deadline = None if args.duration is None else time.monotonic() + args.duration
            print(f'recording into {args.out} (Ctrl-C to stop)', flush=True)
            while not stop.requested and node.error is None:
                if deadline is not None and time.monotonic() >= deadline:
                    break
                executor.spin_once(timeout_sec=0.05)
            if node.error is None and stop.requested:
                _drain(executor, node)
            if node.error is not None:
                raise node.error
        finally:
            try:
                bag.close()
            finally:
                if node is not None:
                    node.destroy_node()
    counts = ', '.join(f'{t} {n}' for t, n in sorted(node.received.items())) or 'nothing'
    print(f'recorded {bag.message_count} messages into {args.out}: {counts}')
    for topic in node.missing():
        print(f'warning: {topic} never appeared')
    return 0


#: After Ctrl-C the recorder keeps taking messages until none came for this long, s ...
DRAIN_QUIET_S = 0.2
#: ... but no longer than this, s (a stop is obeyed within 2 s, also under steady traffic).
DRAIN_MAX_S = 1.0


def _drain(executor: Any, node: Any) -> None:
    """Writes the messages already on their way: queued, or sent and not yet delivered.

    Without it the last messages a publisher sent just before the stop would be lost.
    """
    deadline = time.monotonic() + DRAIN_MAX_S
    seen = sum(node.received.values())
    quiet_since = time.monotonic()
    while node.error is None and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.02)
        now_seen = sum(node.received.values())
        if now_seen != seen:
            seen, quiet_since = now_seen, time.monotonic()
        elif time.monotonic() - quiet_since >= DRAIN_QUIET_S:
            return
