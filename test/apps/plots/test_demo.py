import numpy as np
import pytest

from lumpbeam_ros.apps.plots.demo import plot_measured_vs_predicted, prediction_residual
from lumpbeam_ros.base.errors import LumpbeamError


def test_residual_aligns_by_stamp_inside_the_prediction():
    t_meas = np.arange(0.0, 2.0, 0.01)
    t_pred = np.arange(0.5, 1.5, 0.003)  # another rate, a shorter span
    residual = prediction_residual(t_meas, 2.0 * t_meas + 0.001, t_pred, 2.0 * t_pred)
    assert residual.t[0] >= 0.5 and residual.t[-1] <= 1.5
    np.testing.assert_allclose(residual.residual, 0.001, atol=1e-12)  # linear: exact
    assert residual.rms() == pytest.approx(0.001)
    assert np.isnan(residual.rms(start=5.0))


@pytest.mark.parametrize(
    ('t_pred', 'z_pred', 'message'),
    [
        (np.array([5.0, 6.0]), np.zeros(2), 'do not overlap'),
        (np.array([0.5]), np.zeros(1), 'at least 2'),
        (np.array([0.0, 1.0]), np.zeros(3), 'same length'),
    ],
)
def test_residual_rejects_unusable_series(t_pred, z_pred, message):
    t = np.linspace(0.0, 1.0, 10)
    with pytest.raises(LumpbeamError, match=message):
        prediction_residual(t, np.zeros(10), t_pred, z_pred)


def test_plot_writes_the_figure(tmp_path):
    t = np.arange(0.0, 4.0, 1 / 180)
    z = -0.03 + 0.04 * np.exp(-0.05 * t) * np.cos(2 * np.pi * 3.06 * t)
    residual = prediction_residual(t, z + 1e-5, t, z)
    full = plot_measured_vs_predicted(residual, tmp_path / 'sub' / 'full.png', release_time_s=2.0)
    zoom = plot_measured_vs_predicted(residual, tmp_path / 'zoom.svg', span=(1.0, 2.0))
    assert full.read_bytes()[:8] == b'\x89PNG\r\n\x1a\n' and full.stat().st_size > 10_000
    assert b'<svg' in zoom.read_bytes()[:500]
    with pytest.raises(LumpbeamError, match='no aligned samples'):
        plot_measured_vs_predicted(residual, tmp_path / 'none.png', span=(10.0, 11.0))
