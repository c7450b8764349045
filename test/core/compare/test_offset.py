import numpy as np
import pytest

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.compare.offset import check_overlap, coarse_offset
from lumpbeam_ros.core.compare.rigid import point_spread
from lumpbeam_ros.core.compare.streams import GapInterpolator, clean_track
from lumpbeam_ros.core.synthetic.reference_sensor import ReferenceSensorOptions

from .helpers import make_pair


@pytest.mark.parametrize('offset', [-0.25, 0.0, 7.3e-3, 0.4])
def test_cross_correlation_finds_the_offset(offset):
    pair = make_pair(ReferenceSensorOptions(clock_offset_s=offset), duration=4.0)
    spread = point_spread(pair.reference.points)
    coarse = coarse_offset(pair.camera, GapInterpolator(pair.reference), spread, 1.0)
    # A tenth of the 1 ms lag step: the parabola through the peak does the rest.
    assert coarse.offset_s == pytest.approx(offset, abs=1e-4)
    assert abs(coarse.correlation) > 0.999


def test_streams_that_never_overlap(pair):
    late = clean_track(pair.reference.t + 50.0, pair.reference.points, 'tracker', '/tracker/point')
    with pytest.raises(LumpbeamError, match='never overlap'):
        check_overlap(pair.camera, late, 1.0)
    check_overlap(pair.camera, late, 60.0)


def test_unrelated_motion_is_rejected(pair):
    # Something else swinging at 7.7 Hz and 1.3 Hz: not the beam.
    t = pair.reference.t
    swing = np.column_stack(
        [5e-3 * np.sin(2 * np.pi * 7.7 * t), 2e-3 * np.cos(2 * np.pi * 1.3 * t), 0 * t]
    )
    other = clean_track(t, swing, 'tracker', '/tracker/point')
    with pytest.raises(LumpbeamError, match='do not move together'):
        coarse_offset(pair.camera, GapInterpolator(other), point_spread(swing), 0.5)
