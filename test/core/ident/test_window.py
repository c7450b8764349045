import math

import numpy as np
import pytest

from lumpbeam_ros.core.ident.identification import Status
from lumpbeam_ros.core.ident.identify import identify
from lumpbeam_ros.core.ident.settings import IdentifierConfig
from lumpbeam_ros.core.ident.window import SlidingWindow
from lumpbeam_ros.core.model.parameters import BeamParameters


def test_rejections_are_counted_not_raised():
    w = SlidingWindow(length_s=1.0, max_rate_hz=10.0)
    assert w.push(1.0, 0.1, 0.0)
    assert not w.push(1.0, 0.2, 0.0)  # duplicate
    assert not w.push(0.5, 0.2, 0.0)  # out of order, within the jump
    assert not w.push(2.0, math.nan, 0.0)
    assert not w.push(math.inf, 0.1, 0.0)
    assert w.push(1.1, 0.3, 0.0)
    c = w.counts
    assert (c.kept, c.duplicates, c.out_of_order, c.non_finite) == (2, 1, 1, 2)
    snap = w.snapshot()
    np.testing.assert_array_equal(snap.z, [0.1, 0.3])
    assert snap.counts.non_finite == 2 and snap.counts.duplicates == 2


def test_ring_keeps_the_last_length_s_in_order():
    w = SlidingWindow(length_s=1.0, max_rate_hz=100.0)
    t = np.arange(0.0, 5.0, 0.01)
    for stamp in t:
        w.push(stamp, stamp * 2.0, -stamp)
    snap = w.snapshot()
    expected = t[t >= t[-1] - 1.0 - 1e-12]
    np.testing.assert_allclose(snap.t, expected)
    np.testing.assert_allclose(snap.z, 2.0 * expected)
    np.testing.assert_allclose(snap.pitch, -expected)
    assert np.all(np.diff(snap.t) > 0)


def test_faster_input_than_sized_covers_less_time():
    w = SlidingWindow(length_s=1.0, max_rate_hz=10.0)
    for stamp in np.arange(0.0, 2.0, 0.01):
        w.push(stamp, 0.0)
    assert len(w.snapshot()) == 11  # capacity, not 100 samples


def test_clock_jumping_back_resets():
    w = SlidingWindow(length_s=10.0, max_rate_hz=10.0, reset_jump_back_s=1.0)
    for stamp in range(5, 10):
        w.push(float(stamp), 1.0)
    w.push_load(9.0, 4.5)
    assert not w.push(0.0, 2.0)  # a bag loop, once the next pose agrees
    assert w.push(0.1, 3.0)
    assert w.counts.resets == 1 and len(w) == 2
    snap = w.snapshot()
    # The load still hangs after the jump: its last reading holds from the new stamp on.
    assert snap.z.tolist() == [2.0, 3.0]
    assert snap.loads.t.tolist() == [0.0] and snap.loads.kg.tolist() == [4.5]


def test_loads_keep_the_reading_before_the_window():
    w = SlidingWindow(length_s=2.0, max_rate_hz=10.0)
    for stamp in np.arange(0.0, 10.0, 1.0):
        w.push_load(stamp, 4.5)
    assert not w.push_load(8.5, 4.5) and not w.push_load(9.5, math.nan)
    assert not w.push_load(9.5, -1.0)
    w.push(9.9, 0.0)
    loads = w.snapshot().loads
    assert loads.t.tolist() == [7.0, 8.0, 9.0]  # 7.0 gives the load at the window start
    assert w.counts.loads_rejected == 3


def test_bad_window_settings():
    with pytest.raises(ValueError):
        SlidingWindow(length_s=0.0)


def test_live_stream_identifies_like_a_batch(drop_case):
    trajectory, truth = drop_case()
    trajectory = trajectory.between(0.0, 11.0)  # the window holds 1 s before the release
    config = IdentifierConfig(window_s=10.0)
    window = SlidingWindow.from_config(config)
    for t, z, p, kg in zip(
        trajectory.t, trajectory.z, trajectory.pitch, trajectory.load_kg, strict=True
    ):
        window.push(t, z, p)
        window.push_load(t, kg)
    snap = window.snapshot()
    assert snap.end_s - snap.start_s == pytest.approx(10.0, abs=0.01)
    result = identify(snap, BeamParameters(), config)
    assert result.status == Status.OK, result.message
    assert result.release.source == 'tip_load'
    assert result.estimates.natural_frequency_hz.value == pytest.approx(
        truth.natural_frequency_hz, rel=1e-3
    )
    assert result.estimates.stiffness_total_nm_per_rad.value == pytest.approx(
        truth.stiffness_total_nm_per_rad, rel=0.01
    )


def test_a_second_reading_with_the_same_stamp_replaces_the_first():
    w = SlidingWindow(length_s=2.0, max_rate_hz=10.0)
    w.push(1.0, 0.0)
    assert w.push_load_on_arrival(4.5, 100.0) == (True, 1.0)  # the newest pose's stamp
    assert w.push_load_on_arrival(0.0, 100.1) == (True, 1.0)
    loads = w.snapshot().loads
    assert loads.t.tolist() == [1.0] and loads.kg.tolist() == [0.0]


def test_a_reading_before_any_pose_takes_the_clock():
    w = SlidingWindow(length_s=2.0, max_rate_hz=10.0)
    assert w.push_load_on_arrival(4.5, 7.0) == (True, 7.0)


def test_the_tip_x_is_carried_through_the_ring_and_nan_when_not_given():
    w = SlidingWindow(length_s=1.0, max_rate_hz=10.0)  # 11 slots: 30 pushes wrap the ring
    t = np.arange(30) * 0.1
    for stamp in t:
        assert w.push(stamp, -0.01, 0.0, x=2.3 + stamp)
    assert not w.push(5.0, -0.01, math.nan, x=2.0)  # the pose is judged by z and pitch
    assert w.push(3.0, -0.01, 0.0)
    snap = w.snapshot()
    np.testing.assert_allclose(snap.poses.x[:-1], 2.3 + snap.t[:-1])
    np.testing.assert_allclose(snap.t[:-1], t[t >= 2.0 - 1e-9])
    assert math.isnan(snap.poses.x[-1])


def _two_streams(window, trajectory, behind_s=0.5, other_kg=9.0):
    """Two replays feeding one window: this drop test, and another bag ``behind_s`` behind.

    The other bag's poses arrive late (dropped as out of order), but its /tip_load readings
    count as much as this bag's: the window pairs one bag's poses with the other's load.
    """
    window.push_load_on_arrival(4.5, 0.0)
    window.push_load_on_arrival(other_kg, 0.0)  # the other bag's load, taken as the last one
    released = False
    for t, z, p, kg in zip(
        trajectory.t, trajectory.z, trajectory.pitch, trajectory.load_kg, strict=True
    ):
        if kg == 0.0 and not released:
            window.push_load_on_arrival(0.0, t)
            released = True
        window.push(t, z, p)
        window.push(t - behind_s, z, p)


def test_two_streams_feeding_one_window_are_never_ok(drop_case):
    trajectory, truth = drop_case()
    window = SlidingWindow(length_s=12.5)
    _two_streams(window, trajectory)
    snap = window.snapshot()
    assert snap.counts.duplicates == len(snap)  # every late pose dropped
    result = identify(snap, BeamParameters())
    # The released mass is the other bag's: k_tE is twice the truth, and that must show.
    k = result.estimates.stiffness_total_nm_per_rad.value
    assert k == pytest.approx(2.0 * truth.stiffness_total_nm_per_rad, rel=0.02)
    assert result.status == Status.WARN, result.message
    assert f'dropped {len(snap)} of {2 * len(snap)} poses' in result.message
    assert 'more than 5%: the poses may mix two streams' in result.message


def test_a_window_with_a_few_drops_stays_ok(drop_case):
    trajectory, truth = drop_case()
    window = SlidingWindow(length_s=12.5)
    window.push_load_on_arrival(4.5, 0.0)
    for i, (t, z, p, kg) in enumerate(
        zip(trajectory.t, trajectory.z, trajectory.pitch, trajectory.load_kg, strict=True)
    ):
        if kg == 0.0 and window.snapshot().loads.kg[-1] != 0.0:
            window.push_load_on_arrival(0.0, t)
        window.push(t, z if i % 50 else math.nan, p)  # 2 % dropped
    snap = window.snapshot()
    assert 0.0 < snap.counts.dropped_fraction < 0.05
    result = identify(snap, BeamParameters())
    assert result.status == Status.OK, result.message
    assert result.samples.n_rejected == snap.counts.non_finite > 0
