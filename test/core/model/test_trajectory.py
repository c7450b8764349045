import dataclasses

import numpy as np
import pytest

from lumpbeam_ros.base.interface import BASE_FRAME
from lumpbeam_ros.core.bagio.tipseries import TipSeries
from lumpbeam_ros.core.model.parameters import BeamParameters, DropTestConfig
from lumpbeam_ros.core.model.simulate import simulate_drop_test
from lumpbeam_ros.core.model.trajectory import TipTrajectory

BEAM = BeamParameters()
DROP = DropTestConfig(load_kg=4.5, release_time_s=0.5, duration_s=1.5)


@pytest.fixture(scope='module')
def drop():
    return simulate_drop_test(BEAM, DROP)


def test_a_simulated_drop_is_a_tip_series_with_its_load_and_angles(drop):
    assert isinstance(drop, TipSeries) and drop.frame_id == BASE_FRAME
    n = len(drop)
    assert n == 271 and drop.q.shape == (n, BEAM.n_segments) and drop.load_kg.shape == (n,)
    before = drop.t < DROP.release_time_s
    assert np.all(drop.load_kg[before] == DROP.load_kg) and np.all(drop.load_kg[~before] == 0)


def test_the_pose_is_the_end_of_the_chain_of_its_angles(drop):
    # B.17 chained to the free end: segments of L / n_s at the absolute angles q.
    ls = BEAM.length_m / BEAM.n_segments
    np.testing.assert_allclose(drop.x, ls * np.cos(drop.q).sum(axis=1), rtol=0, atol=1e-12)
    np.testing.assert_allclose(drop.z, -ls * np.sin(drop.q).sum(axis=1), rtol=0, atol=1e-12)
    np.testing.assert_array_equal(drop.pitch, drop.q[:, -1])
    # The tip rises when the load leaves: it sags less after the release.
    assert np.mean(drop.z[drop.t > 1.0]) > drop.z[0]


@pytest.mark.parametrize(
    ('start', 'end', 'count'),
    [(0.0, 0.5, 90), (0.5, 0.6, 18), (0.4999, 0.5001, 1), (2.0, 3.0, 0), (0.6, 0.5, 0)],
)
def test_between_cuts_the_load_and_angles_with_the_poses(drop, start, end, count):
    part = drop.between(start, end)
    assert type(part) is TipTrajectory and len(part) == count
    keep = (drop.t >= start) & (drop.t < end)
    for name in ('t', 'x', 'z', 'pitch', 'load_kg'):
        np.testing.assert_array_equal(getattr(part, name), getattr(drop, name)[keep])
    np.testing.assert_array_equal(part.q, drop.q[keep])
    assert part.q.shape == (count, BEAM.n_segments)


@pytest.mark.parametrize('q', [None, np.empty((0, 10))], ids=['no angles', 'empty angles'])
def test_a_trajectory_without_angles_cuts_as_well(q):
    t = np.arange(5) * 0.1
    trajectory = TipTrajectory(t, t, -t, 0 * t, np.full(5, 2.0), q)
    part = trajectory.select(slice(1, 3))
    np.testing.assert_array_equal(part.t, [0.1, 0.2])
    np.testing.assert_array_equal(part.load_kg, [2.0, 2.0])
    assert part.q is q  # not one entry per sample: kept whole


def test_a_trajectory_is_immutable(drop):
    with pytest.raises(dataclasses.FrozenInstanceError):
        drop.load_kg = np.zeros(3)


def test_the_load_is_required():
    t = np.arange(3.0)
    with pytest.raises(TypeError, match='load_kg'):
        TipTrajectory(t, t, t, t)
