import numpy as np
import pytest

from lumpbeam_ros.errors import LumpbeamError
from lumpbeam_ros.vision.calibration import adjusted_rig, calibrate_rig
from lumpbeam_ros.vision.pose import PlaneModel


@pytest.mark.parametrize('error', [(0.004, -0.003, 0.01), (-0.01, 0.0, -0.02)])
def test_recovers_tilt_and_depth(config, error):
    truth = PlaneModel(config.rig, config.camera_info)
    believed = adjusted_rig(config.rig, *error)
    rng = np.random.default_rng(2)
    poses = [np.array([2.3107, z, 1.5 * z / 2.3107]) for z in np.linspace(-0.05, 0.03, 12)]
    pixels = [truth.project(q) + rng.normal(0, 0.03, (truth.n_points, 2)) for q in poses]
    # Start every frame from the believed rig's 3-DoF fit, as the tracker does.
    model = PlaneModel(believed, config.camera_info)
    starts = [model.fit(p, q).pose for p, q in zip(pixels, poses, strict=True)]
    result = calibrate_rig(believed, config.camera_info, pixels, starts)
    assert np.all(np.abs(np.array(result.tilt_rad) + error[:2]) < 5 * result.std[:2])
    assert result.depth_offset_m == pytest.approx(-error[2], abs=5 * result.std[2])
    assert result.std[2] < 2e-4
    assert result.rms_px < 0.05


def test_needs_three_frames(config):
    with pytest.raises(LumpbeamError, match='at least 3'):
        calibrate_rig(config.rig, config.camera_info, [np.zeros((48, 2))] * 2, [np.zeros(3)] * 2)
