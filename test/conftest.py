"""Shared fixtures: the launch-free ROS graph of :mod:`harness`."""

from harness import ros_graph  # noqa: F401  (registers the fixture for every test)

