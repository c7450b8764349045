"""The vision tests' camera set-up (test/core/vision/conftest.py), shared with the lab's tests."""

from core.vision.conftest import config, drop_test, no_calibration, rest_pose  # noqa: F401
