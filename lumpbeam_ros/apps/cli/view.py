"""``lumpbeam view [--bag BAG [--arm FILE]] [--port 8765]``: the live graph, or a bag, served.

``--arm FILE`` draws a recorded arm's bag (``/joint_states``, ``/tip_pose``, no markers): the
arm of the file moved along the bag's joint angles, on ``/beam_markers``
(:mod:`lumpbeam_ros.core.viz.arm_scenes`).

Open Foxglove, connect to ``ws://localhost:8765`` (Open connection, Foxglove WebSocket) and
import ``config/foxglove_layout.json``. No ROS installation is needed for a bag; the live
graph is read with rclpy. Stops on Ctrl-C or SIGTERM (or after ``--duration``).
"""

from __future__ import annotations

import argparse
import signal
import sys
import time
from typing import Any

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import BEAM_MARKERS, MARKER_ARRAY


def run(args: argparse.Namespace) -> int:
    """Serves until stopped.

    Returns:
        0 when stopped by Ctrl-C, SIGTERM, ``--duration`` or the bag's end.

    Raises:
        LumpbeamError: The port is taken, the bag cannot be read or lacks a topic.
    """
    from lumpbeam_ros.core.bagio import BagReader
    from lumpbeam_ros.nodes.foxglove_server import (
        ChannelSink,
        open_bag_channels,
        replay_bag,
        start_server,
    )

    reader = BagReader(args.bag) if args.bag is not None else None  # bad bag: before binding
    markers = _arm_markers(reader, args.arm) if args.arm is not None else []
    stop = {'requested': False}
    deadline = None if args.duration is None else time.monotonic() + args.duration

    def should_stop() -> bool:
        return stop['requested'] or (deadline is not None and time.monotonic() > deadline)

    def request_stop(_signum: int, _frame: Any) -> None:
        stop['requested'] = True

    previous = {s: signal.signal(s, request_stop) for s in (signal.SIGINT, signal.SIGTERM)}
    server = start_server(args.host, args.port)
    sink = ChannelSink()
    try:
        if reader is not None:
            topics = open_bag_channels(reader, sink, args.topics)
            if markers:
                topics = [t for t in topics if t != BEAM_MARKERS]  # drawn anew
                if not sink.has_topic(BEAM_MARKERS):
                    sink.add_topic(BEAM_MARKERS, MARKER_ARRAY)
            _announce(server.port, args.host, f'{reader.path} ({len(topics)} topics)')
            replay_bag(
                reader, sink, topics, rate=args.rate, loop=args.loop, should_stop=should_stop,
                extra=markers,
            )  # fmt: skip
        else:
            _announce(server.port, args.host, 'the live ROS graph')
            _serve_graph(sink, args.topics, should_stop)
    finally:
        sink.close()
        server.stop()
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    print(f'lumpbeam view: stopped after {sum(sink.sent.values())} messages', flush=True)
    return 0


def _arm_markers(reader: Any, arm: str) -> list[Any]:
    """``--arm``: the arm of the file drawn along the bag's joint states."""
    from lumpbeam_ros.core.model.arm.config import load_arm_config
    from lumpbeam_ros.core.viz.arm_scenes import recorded_arm_markers

    if reader is None:
        raise LumpbeamError('--arm draws a bag: give --bag too')
    markers = recorded_arm_markers(reader, load_arm_config(arm))
    print(f'lumpbeam view: {len(markers)} marker arrays of the arm of {arm}', flush=True)
    return markers


def _announce(port: int, host: str, what: str) -> None:
    print(f'lumpbeam view: serving {what} at ws://{host}:{port}', flush=True)


def _serve_graph(sink: Any, topics: list[str] | None, should_stop: Any) -> None:
    """Forwards the live graph's topics as they appear (the recorder's discovery)."""
    import rclpy
    from rclpy.signals import SignalHandlerOptions

    from lumpbeam_ros.nodes.recorder import Recorder

    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    node = None
    try:
        node = Recorder(sink, topics)
        while not should_stop():
            rclpy.spin_once(node, timeout_sec=0.1)
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    print(f'lumpbeam view: forwarded {node.received if node else {}}', file=sys.stderr)
