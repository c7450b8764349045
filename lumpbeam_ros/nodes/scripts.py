"""The nodes' console scripts (``setup.py``): signal handlers first, then the node's modules.

A console script imports its target's module before calling it; a node's module imports
rclpy, numpy and scipy, seconds on a loaded machine. These functions import only the
standard library, so :func:`~lumpbeam_ros.base.interrupts.run_script` handles SIGINT and SIGTERM
from the first moment: a signal during the imports ends the node quietly with exit code 0,
as one during its spin does (:func:`~lumpbeam_ros.nodes.lifecycle.run_node`).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable

from lumpbeam_ros.base.interface import (
    CAMERA_NODE,
    DIAGNOSIS_NODE,
    IDENTIFIER_NODE,
    SHAPER_NODE,
    SIMULATOR_NODE,
)
from lumpbeam_ros.base.interrupts import run_script


def _run(node: str) -> int:
    """Runs ``lumpbeam_ros.nodes.<node>``'s ``main`` (each node's module bears its name)."""

    def load() -> Callable[[], int]:
        main: Callable[[], int] = importlib.import_module(f'lumpbeam_ros.nodes.{node}').main
        return main

    return run_script(load, lambda _signum: 0)


def camera_node() -> int:
    """``camera_node`` (:mod:`lumpbeam_ros.nodes.camera_node`)."""
    return _run(CAMERA_NODE)


def identifier_node() -> int:
    """``identifier_node`` (:mod:`lumpbeam_ros.nodes.identifier_node`)."""
    return _run(IDENTIFIER_NODE)


def simulator_node() -> int:
    """``simulator_node`` (:mod:`lumpbeam_ros.nodes.simulator_node`)."""
    return _run(SIMULATOR_NODE)


def diagnosis_node() -> int:
    """``diagnosis_node`` (:mod:`lumpbeam_ros.nodes.diagnosis_node`)."""
    return _run(DIAGNOSIS_NODE)


def shaper_node() -> int:
    """``shaper_node`` (:mod:`lumpbeam_ros.nodes.shaper_node`)."""
    return _run(SHAPER_NODE)
