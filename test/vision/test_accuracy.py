import numpy as np
import pytest

from lumpbeam_ros.errors import LumpbeamError
from lumpbeam_ros.vision.accuracy import measure_accuracy, stand_in_drop_trajectory


def test_stand_in_trajectory_shape():
    trajectory = stand_in_drop_trajectory(duration_s=2.0)
    assert len(trajectory) == 360
    assert trajectory.z[0] == pytest.approx(-0.05)
    assert np.mean(trajectory.z[-90:]) == pytest.approx(-0.01, abs=0.005)
    np.testing.assert_allclose(trajectory.pitch, 1.5 * trajectory.z / 2.3107)
    assert np.ptp(trajectory.x) < 1e-3


def test_full_resolution_meets_the_targets():
    """2048 x 2048, 2 DN noise, blur, 1 ms exposure, a rig mis-configured out of plane."""
    report = measure_accuracy(2048, 2048, n_frames=64)
    print(report.summary())
    assert report.frames_lost == 0
    assert report.frames_calibrating == 30
    assert report.z_rms_um <= 10.0
    assert report.pitch_rms_mrad <= 0.05
    # The covariance is honest to within a factor of a few.
    assert 0.3 < report.z_sigma_um / report.z_rms_um < 5.0


@pytest.mark.parametrize(('width', 'height', 'z_limit_um'), [(1024, 1024, 10.0), (640, 480, 20.0)])
def test_lower_resolutions(width, height, z_limit_um):
    report = measure_accuracy(width, height, n_frames=80)
    print(report.summary())
    assert report.frames_lost == 0
    assert report.z_rms_um <= z_limit_um
    assert report.pitch_rms_mrad <= 0.1


def test_bad_trajectory_arguments():
    with pytest.raises(LumpbeamError):
        stand_in_drop_trajectory(duration_s=0.0)
