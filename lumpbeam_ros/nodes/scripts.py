"""The nodes' console scripts (``setup.py``): signal handlers first, then the node's modules.

A console script imports its target's module before calling it; a node's module imports
rclpy, numpy and scipy, seconds on a loaded machine. These functions import only the
standard library, so :func:`~lumpbeam_ros.interrupts.run_script` handles SIGINT and SIGTERM
from the first moment: a signal during the imports ends the node quietly with exit code 0,
as one during its spin does (:func:`~lumpbeam_ros.nodes.lifecycle.run_node`).
"""

from __future__ import annotations

import importlib
from collections.abc import Callable

from lumpbeam_ros.interrupts import run_script


def _run(module: str) -> int:
    def load() -> Callable[[], int]:
        main: Callable[[], int] = importlib.import_module(f'lumpbeam_ros.nodes.{module}').main
        return main

    return run_script(load, lambda _signum: 0)


def camera_node() -> int:
    """``camera_node`` (:mod:`lumpbeam_ros.nodes.camera_node`)."""
    return _run('camera_node')


def identifier_node() -> int:
    """``identifier_node`` (:mod:`lumpbeam_ros.nodes.identifier_node`)."""
    return _run('identifier_node')


def simulator_node() -> int:
    """``simulator_node`` (:mod:`lumpbeam_ros.nodes.simulator_node`)."""
    return _run('simulator_node')


def diagnosis_node() -> int:
    """``diagnosis_node`` (:mod:`lumpbeam_ros.nodes.diagnosis_node`)."""
    return _run('diagnosis_node')


def shaper_node() -> int:
    """``shaper_node`` (:mod:`lumpbeam_ros.nodes.shaper_node`)."""
    return _run('shaper_node')
