import numpy as np
import pytest

from lumpbeam_ros.base.errors import BagError
from lumpbeam_ros.core.bagio import BagWriter
from lumpbeam_ros.core.compare.bag_comparison import read_comparison_input


def _write(path, camera=True, tracker=True, loads=True, frame='beam_base', n=40):
    with BagWriter(path) as bag:
        for i in range(n):
            t = 0.01 * i
            if loads and i % 10 == 0:
                bag.write_float('/tip_load', t, 4.5)
            if camera:
                bag.write_pose('/tip_pose', t, 2.3, -0.05 + 0.01 * np.sin(t), 0.01, frame)
            if tracker:
                bag.write_point('/tracker/point', t + 0.005, 1.0, 2.0, 3.0 + t, 'tracker')


def test_reads_both_sensors_and_loads(tmp_path):
    _write(tmp_path / 'bag')
    streams = read_comparison_input(tmp_path / 'bag')
    assert len(streams.camera) == len(streams.reference) == 40
    assert streams.camera.frame_id == 'beam_base' and streams.reference.frame_id == 'tracker'
    assert np.all(streams.camera.points[:, 1] == 0.0)
    assert np.allclose(streams.camera.points[:, 0], 2.3)
    assert streams.reference.t[0] == pytest.approx(0.005)
    assert list(streams.loads.kg) == [4.5] * 4


def test_loads_are_optional(tmp_path):
    _write(tmp_path / 'bag', loads=False)
    assert read_comparison_input(tmp_path / 'bag').loads is None


@pytest.mark.parametrize(
    ('kwargs', 'message'),
    [
        ({'tracker': False}, r'no reference sensor \(/tracker/point\)'),
        ({'camera': False}, r'no camera poses \(/tip_pose\)'),
        ({'camera': False, 'tracker': False}, 'no camera poses .* and no reference sensor'),
        ({'frame': 'camera'}, "frame 'camera', not 'beam_base'"),
        ({'n': 5}, '5 valid samples, need at least'),
    ],
)
def test_bad_bags(tmp_path, kwargs, message):
    _write(tmp_path / 'bag', **kwargs)
    with pytest.raises(BagError, match=message):
        read_comparison_input(tmp_path / 'bag')
