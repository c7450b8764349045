"""Shared fixtures: the launch-free ROS graph of :mod:`harness`, ``mcap doctor``, the demo."""

from demo_results import demo_results  # noqa: F401  (the session's one demo run)
from harness import ros_domain_id, ros_graph  # noqa: F401  (registers the fixtures for every test)
from mcap_doctor import mcap_doctor  # noqa: F401  (registers the fixture for every test)
