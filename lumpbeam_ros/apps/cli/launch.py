"""``lumpbeam launch FILE [NAME:=VALUE ...]``: a ROS 2 YAML launch file's nodes, started.

Where ROS's own ``launch`` is missing (pip does not have it): each node is a child process,
and all are stopped together.
"""

from __future__ import annotations

import argparse
import signal
import subprocess
import time
from typing import Any

from lumpbeam_ros.apps.demo.graph import launched_command
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.nodes.launch_file import parse_assignments, read_launch_file

#: How often the children are looked at, s.
POLL_S = 0.1
#: How long the children have to stop after SIGINT before they are killed, s.
STOP_GRACE_S = 10.0


def run(args: argparse.Namespace) -> int:
    """Starts the file's nodes and runs until Ctrl-C, SIGTERM or a node's exit.

    Returns:
        0 when stopped by a signal or when every node ended by itself with code 0.

    Raises:
        LumpbeamError: The file cannot be read, or a node exited with an error (the others
            are stopped first).
    """
    plan = read_launch_file(args.file, parse_assignments(args.arguments))
    stop = {'requested': False}

    def request_stop(_signum: int, _frame: Any) -> None:
        stop['requested'] = True

    previous = {s: signal.signal(s, request_stop) for s in (signal.SIGINT, signal.SIGTERM)}
    children: list[tuple[str, subprocess.Popen[bytes]]] = []
    ended: tuple[str, int] | None = None
    try:
        for node in plan.nodes:
            children.append((node.label, subprocess.Popen(launched_command(node))))
        labels = ', '.join(label for label, _ in children)
        print(f'lumpbeam launch: started {labels} from {plan.source}', flush=True)
        while not stop['requested'] and ended is None:
            ended = next(
                ((label, code) for label, c in children if (code := c.poll()) is not None), None
            )
            time.sleep(POLL_S)
    finally:
        _stop_all(children)
        for sig, handler in previous.items():
            signal.signal(sig, handler)
    if ended is not None and ended[1] != 0:
        raise LumpbeamError(f'{ended[0]} exited with code {ended[1]}; the other nodes stopped')
    print(f'lumpbeam launch: stopped {len(children)} nodes', flush=True)
    return 0


def _stop_all(children: list[tuple[str, subprocess.Popen[bytes]]]) -> None:
    """Interrupts every child still running, and kills what has not stopped in time."""
    for _, child in children:
        if child.poll() is None:
            child.send_signal(signal.SIGINT)
    deadline = time.monotonic() + STOP_GRACE_S
    for label, child in children:
        try:
            child.wait(max(deadline - time.monotonic(), 0.0))
        except subprocess.TimeoutExpired:
            child.kill()
            child.wait()
            print(f'lumpbeam launch: {label} did not stop in {STOP_GRACE_S:g} s: killed')
