import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.compare.align import AlignOptions, align_streams
from lumpbeam_ros.core.compare.streams import clean_track
from lumpbeam_ros.core.synthetic.reference_sensor import ReferenceSensorOptions

from .helpers import make_pair, with_reference

TRACKERS = {
    'default': ReferenceSensorOptions(),
    'near, upside down': ReferenceSensorOptions(
        position_m=(0.5, 1.5, -1.0), rotation_deg=(170.0, 30.0, -60.0), clock_offset_s=-0.0421
    ),
    'far, noisier': ReferenceSensorOptions(
        position_m=(4.0, -6.0, 1.0), rotation_deg=(0.0, 0.0, 180.0), noise_m=30e-6
    ),
}


def _check_alignment(alignment, tracker, pair):
    truth = tracker.transform
    # The offset: well within 0.2 ms, and within 5 of its own standard deviations.
    error = alignment.offset_s - tracker.clock_offset_s
    assert abs(error) < 0.2e-3
    assert abs(error) < 5.0 * alignment.offset_std_s + 1e-7
    # The rotation, axis by axis against its std; the vertical axis is the weak one.
    rotvec = Rotation.from_matrix(alignment.transform.rotation @ truth.rotation.T).as_rotvec()
    assert np.all(np.abs(rotvec) < 5.0 * alignment.rotation_std_rad)
    assert alignment.transform.angle_to(truth) < np.radians(0.3)
    # Where the tip moves, the frames agree to far better than 0.1 mm.
    tip = pair.samples.true_points
    mapped = alignment.transform.apply(truth.inverse().apply(tip))
    assert np.max(np.linalg.norm(mapped - tip, axis=1)) < 0.1e-3
    # The tracker origin: only as good as the rotation times the distance to it.
    assert np.all(
        np.abs(alignment.transform.translation - truth.translation)
        < 5.0 * alignment.translation_std_m
    )


@pytest.mark.parametrize('name', list(TRACKERS))
def test_offset_and_transform_are_recovered(name):
    tracker = TRACKERS[name]
    pair = make_pair(tracker)
    aligned = align_streams(pair.camera, pair.reference)
    _check_alignment(aligned.alignment, tracker, pair)
    assert aligned.alignment.rotation_std_rad[2] > 10 * aligned.alignment.rotation_std_rad[0]


def test_dropouts_are_skipped(pair):
    t = pair.reference.t
    keep = np.ones(t.size, bool)
    for start in (1.0, 2.3, 3.1, 4.72):  # 30-80 ms dropouts, one across the release
        keep &= ~((t > start) & (t < start + 0.03 + 0.01 * start))
    keep &= np.random.default_rng(3).random(t.size) > 0.05  # and 5 % single losses
    gappy = with_reference(pair, keep)
    aligned = align_streams(pair.camera, gappy)
    assert aligned.reference.gap_count >= 4
    pairs = aligned.alignment.pairs
    assert 0.9 * pairs.size < np.count_nonzero(pairs) < pairs.size - 20
    _check_alignment(aligned.alignment, pair.tracker, pair)


def test_a_gap_larger_than_max_gap_is_not_bridged(pair):
    keep = np.ones(pair.reference.t.size, bool)
    keep[1000:1004] = False  # 5 ms
    options = AlignOptions(max_gap_s=0.004)
    aligned = align_streams(pair.camera, with_reference(pair, keep), options)
    assert aligned.reference.gap_count == 1
    assert np.count_nonzero(~aligned.alignment.pairs) >= 3


@pytest.mark.parametrize(
    ('edit', 'message'),
    [
        ('identical', 'do not move'),
        ('line', 'lie on a line'),
        ('camera still', 'tip does not move'),
    ],
)
def test_frames_that_cannot_be_aligned(pair, edit, message):
    camera, reference = pair.camera, pair.reference
    if edit == 'identical':
        reference = with_reference(
            pair, slice(None), np.tile([1.0, 2.0, 3.0], (len(reference), 1))
        )
    elif edit == 'line':
        direction = np.array([0.6, 0.0, 0.8])
        z = pair.samples.true_points[:, 2]
        noise = 15e-6 * np.random.default_rng(4).standard_normal((z.size, 3))
        reference = with_reference(pair, slice(None), z[:, None] * direction + noise)
    else:
        still = np.tile(camera.points[0], (len(camera), 1))
        camera = clean_track(camera.t, still, 'beam_base', '/tip_pose')
    with pytest.raises(LumpbeamError, match=message):
        align_streams(camera, reference)


def test_bad_options():
    with pytest.raises(LumpbeamError, match='max offset'):
        AlignOptions(max_offset_s=0.0)
    with pytest.raises(LumpbeamError, match='max gap'):
        AlignOptions(max_gap_s=-1.0)


def test_clock_drift_inflates_the_offset_std(pair):
    # The tracker clock runs 100 ppm fast: the offset wanders by 0.6 ms over the record.
    ref = pair.reference
    drifting = clean_track(ref.t * (1.0 + 1e-4), ref.points, ref.frame_id, ref.source)
    alignment = align_streams(pair.camera, drifting).alignment
    assert alignment.offset_consistency > 5.0
    assert alignment.offset_std_s > 5.0 * alignment.offset_std_white_s
    # The offset where the tip moves (after the release at 2 s): the drift at 3..5 s.
    assert 7.3e-3 + 3e-4 < alignment.offset_s < 7.3e-3 + 5e-4


def test_white_noise_segments_agree(pair):
    alignment = align_streams(pair.camera, pair.reference).alignment
    assert 0.3 < alignment.offset_consistency < 2.0
    assert alignment.offset_std_s >= alignment.offset_std_white_s
