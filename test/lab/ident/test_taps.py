import numpy as np
import pytest

from lumpbeam_lab.ident.taps import Tap


@pytest.mark.parametrize('seed', [0, 1])
def test_a_tap_rings_from_its_instant_at_the_rate_and_within_the_sensor(seed):
    tap = Tap(1000, 2, (0.5,), ((10.0, 0.01, 1.0),), step=0.01, clip=0.8)
    t, y = tap.record(seed)
    assert t.size == 2000 and np.allclose(np.diff(t), 1e-3)
    assert np.all(y[t < 0.5] == 0.0) and np.ptp(y[t >= 0.5]) > 1.0
    assert np.allclose(y / 0.01, np.round(y / 0.01)) and np.abs(y).max() == 0.8


def test_a_line_runs_through_the_whole_record():
    t, y = Tap(1000, 2, (), (), hum=(50.0, 0.2)).record()
    assert np.std(y) == pytest.approx(0.2 / np.sqrt(2), rel=1e-2)
