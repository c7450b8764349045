"""How every node process runs: init, build the node, spin, count, shut down.

One place for what each node's ``main`` did alike: a configuration error while the node is
built is one line on stderr and exit code 2 (no traceback); Ctrl-C or an external shutdown
ends the spin quietly; what the node published is written for the demo's per-topic counts
(:mod:`lumpbeam_ros.nodes.counts`) however it stopped.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Mapping, Sequence
from typing import TypeVar

import rclpy
from rclpy.exceptions import ParameterException
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node

from lumpbeam_ros.errors import LumpbeamError
from lumpbeam_ros.nodes.counts import write_counts

#: Exit code of a node whose configuration is invalid.
CONFIG_ERROR = 2

_N = TypeVar('_N', bound=Node)


def run_node(
    name: str,
    make: Callable[[], _N],
    published: Callable[[_N], Mapping[str, int]],
    args: Sequence[str] | None = None,
    run: Callable[[_N], None] = rclpy.spin,
    received: Callable[[_N], Mapping[str, int]] | None = None,
) -> int:
    """Runs one node process until it is stopped.

    Args:
        name: The node's name, the prefix of its error line and the name of its counts.
        make: Builds the node (after ``rclpy.init``).
        published: Messages published per topic, read when the node stops.
        args: Command-line arguments (default ``sys.argv``), incl. ``--ros-args``.
        run: What to do with the node (default: spin it until shutdown).
        received: Messages received per topic, read when the node stops.

    Returns:
        0 after a clean stop, :data:`CONFIG_ERROR` when the node cannot be built or ``run``
        fails on its configuration.
    """
    rclpy.init(args=list(args) if args is not None else None)
    node: _N | None = None
    try:
        node = make()
        run(node)
    except (LumpbeamError, ParameterException) as exc:
        print(f'{name}: error: {exc}', file=sys.stderr)
        return CONFIG_ERROR
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            write_counts(name, published(node), received(node) if received else None)
            node.destroy_node()
        rclpy.try_shutdown()
    return 0
