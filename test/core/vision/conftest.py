"""Shared fixtures for the vision tests: a small camera set-up rendered fast."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from lumpbeam_lab.camera.accuracy import drop_test_trajectory
from lumpbeam_ros.core.model.trajectory import TipTrajectory
from lumpbeam_ros.core.vision.config import CameraConfig, load_camera_config


@pytest.fixture(scope='session')
def config() -> CameraConfig:
    """The package's camera config at 640 x 480 (the focal length scales with the width)."""
    return load_camera_config().with_resolution(640, 480)


@pytest.fixture(scope='session')
def rest_pose() -> np.ndarray:
    """A tip pose near the middle of the drop test's travel."""
    return np.array([2.3107, -0.012, 0.004])


@pytest.fixture(scope='session')
def no_calibration(config: CameraConfig) -> CameraConfig:
    """The config with the rig trusted as configured (no calibration phase)."""
    return dataclasses.replace(
        config, tracker=dataclasses.replace(config.tracker, calibration_frames=0)
    )


@pytest.fixture(scope='session')
def drop_test() -> TipTrajectory:
    """The model's 12 s drop test (the identified beam, 4.5 kg released at 2 s)."""
    return drop_test_trajectory()
