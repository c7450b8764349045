"""Shared fixtures: the launch-free ROS graph of :mod:`harness`."""

import pytest
from harness import ros_graph  # noqa: F401  (registers the fixture for every test)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Leaves the slow validation matrices out unless ``-m`` names them (``-m slow``)."""
    if 'slow' in (config.getoption('markexpr') or ''):
        return
    skip = pytest.mark.skip(reason='slow validation: run with -m slow')
    for item in items:
        if 'slow' in item.keywords:
            item.add_marker(skip)
