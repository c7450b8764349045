"""Shared fixtures: the launch-free ROS graph of :mod:`harness`, ``mcap doctor``, the demo.

ROS is imported only by the tests that take a ROS fixture (or import :mod:`harness`
themselves), so the tests of the ROS-free floors run in a plain Python.
"""

from collections.abc import Iterator
from typing import Any

import pytest
from demo_results import demo_results  # noqa: F401  (the session's one demo run)
from mcap_doctor import mcap_doctor  # noqa: F401  (registers the fixture for every test)


@pytest.fixture
def ros_graph(monkeypatch: pytest.MonkeyPatch) -> Iterator[Any]:
    """A private ROS graph for one test (:class:`harness.RosGraph`)."""
    from harness import open_ros_graph

    yield from open_ros_graph(monkeypatch)


@pytest.fixture
def ros_domain_id() -> Iterator[int]:
    """A domain id held for one test, for ROS code the test does not give a context to."""
    from harness import held_domain_id

    yield from held_domain_id()
