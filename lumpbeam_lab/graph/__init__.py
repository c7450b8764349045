"""Runs of the live graph that prove it (they talk to rclpy, so they stay out of mypy's core)."""
