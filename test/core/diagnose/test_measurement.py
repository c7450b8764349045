import numpy as np
import pytest

from lumpbeam_ros.base.errors import BagError, LumpbeamError
from lumpbeam_ros.core.bagio import BagWriter
from lumpbeam_ros.core.diagnose.measurement import make_record, read_record, tracked_segments
from lumpbeam_ros.core.model.parameters import DropTestConfig, load_beam_config
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, write_drop_test_bag

T = np.arange(0.0, 6.0, 1.0 / 180.0)


def _record(**changes):
    args = {
        't': T,
        'z': np.zeros(T.size),
        'pitch': np.zeros(T.size),
        'initial_load_kg': 4.5,
        'load_events': [(2.0, 0.0)],
    }
    args.update(changes)
    return make_record(**args)


def test_a_valid_record_keeps_its_event_and_drops_bad_samples():
    z = np.zeros(T.size)
    z[5] = np.nan
    record = _record(z=z, load_events=[(2.0, 0.0), (-1.0, 4.5), (99.0, 1.0)])
    assert len(record) == T.size - 1
    assert record.initial_load_kg == 4.5
    assert record.load_events == ((2.0, 0.0),)
    assert record.rate_hz == pytest.approx(180.0)


@pytest.mark.parametrize(
    ('changes', 'message'),
    [
        ({'load_events': []}, 'never changes'),
        ({'load_events': [(2.0, 4.5)]}, 'never changes'),
        ({'load_events': [(5.5, 0.0)]}, 'poses after the last load change'),
        ({'load_events': [(2.0, -1.0)]}, 'is not valid'),
        ({'load_events': [(2.0, float('nan'))]}, 'is not valid'),
        ({'initial_load_kg': -2.0}, 'initial tip load'),
        ({'z': np.zeros(10)}, 'differ in length'),
        ({'t': T[:100], 'z': np.zeros(100), 'pitch': np.zeros(100)}, 'valid tip poses'),
    ],
)
def test_unusable_records_are_refused_with_a_reason(changes, message):
    with pytest.raises(LumpbeamError, match=message):
        _record(**changes)


def test_reads_poses_and_load_changes_from_a_bag(tmp_path):
    beam, _ = load_beam_config()
    drop = DropTestConfig(release_time_s=1.0)
    write_drop_test_bag(tmp_path / 'bag', beam, drop, SynthOptions(duration_s=4.0))
    record = read_record(tmp_path / 'bag')
    assert record.initial_load_kg == 4.5
    assert record.load_events == ((1.0, 0.0),)
    assert len(record) == 4 * 180 + 1
    assert record.z[0] == pytest.approx(-0.0694, abs=5e-4)


def test_bag_without_a_drop_or_without_loads_is_a_bag_error(tmp_path):
    with BagWriter(tmp_path / 'still') as bag:
        for i, t in enumerate(T):
            if i % 180 == 0:
                bag.write_float('/tip_load', t, 4.5)
            bag.write_pose('/tip_pose', t, 2.3, -0.07, 0.04)
    with pytest.raises(BagError, match='never changes'):
        read_record(tmp_path / 'still')
    with BagWriter(tmp_path / 'poses_only') as bag:
        for t in T:
            bag.write_pose('/tip_pose', t, 2.3, -0.07, 0.04)
    with pytest.raises(BagError, match='tip_load'):
        read_record(tmp_path / 'poses_only')


def test_poses_in_another_frame_are_refused(tmp_path):
    with BagWriter(tmp_path / 'camera') as bag:
        bag.write_float('/tip_load', 0.0, 4.5)
        for t in T:
            bag.write_pose('/tip_pose', t, 2.3, -0.07, 0.04, frame='camera')
    with pytest.raises(BagError, match='frame'):
        read_record(tmp_path / 'camera')


@pytest.mark.parametrize(
    ('lost', 'starts'),
    [
        ([], [0]),  # tracked throughout
        ([(100, 110)], [0, 110]),  # one loss: a new stretch after it
        ([(100, 110), (112, 114)], [0, 110]),  # a few frames between losses join the next
        ([(100, 110), (595, 597)], [0, 110]),  # a short last stretch stays with the one before
    ],
)
def test_tracked_segments_start_after_each_loss(lost, starts):
    keep = np.ones(600, dtype=bool)
    for a, b in lost:
        keep[a:b] = False
    index = np.flatnonzero(keep)
    labels = tracked_segments(index / 180.0)
    assert np.all(np.diff(labels) >= 0)
    assert [int(index[np.argmax(labels == k)]) for k in range(labels.max() + 1)] == starts


@pytest.mark.parametrize('jump_s', [100.0, 1e6])
def test_a_stamp_jump_keeps_the_stretch_with_the_drop(jump_s):
    t = np.arange(0.0, 12.0, 1.0 / 180.0)
    t[t > 9.0] += jump_s
    record = make_record(t, np.zeros(t.size), np.zeros(t.size), 4.5, [(2.0, 0.0)], 'bag')
    # Simulating the record costs memory in proportion to its span: 9 s, not 1e6 s.
    assert record.t[0] == 0.0 and record.t[-1] == pytest.approx(9.0, abs=0.01)
    assert record.load_events == ((2.0, 0.0),)
    (note,) = record.notes
    assert note.startswith(f'/tip_pose stamps jump by {jump_s:+.3g}')
    assert 'kept 0.000 to 9.000 s (1621 poses), dropped 539' in note


def test_dropped_poses_are_counted_and_said():
    z = np.zeros(T.size)
    z[5:8] = np.nan
    t = T.copy()
    t[20] = t[19]  # a repeated stamp
    record = _record(t=t, z=z)
    assert (record.counts.non_finite, record.counts.duplicates) == (3, 1)
    assert record.counts.received == T.size and len(record) == T.size - 4
    assert record.notes == (
        f'dropped 4 of {T.size} poses (3 with a NaN or inf stamp, position or orientation; '
        '1 with a repeated or out-of-order stamp)',
    )
    assert _record().counts.dropped == 0 and _record().notes == ()


def test_a_record_too_short_after_dropping_poses_says_why():
    z = np.zeros(T.size)
    z[::2] = np.nan  # half the poses lost: too few left after the drop
    with pytest.raises(LumpbeamError, match=r'poses after the last load change') as caught:
        _record(z=z, load_events=[(3.5, 0.0)])
    assert f'(dropped {(T.size + 1) // 2} of {T.size} poses (' in str(caught.value)
    z[: T.size - 100] = np.nan
    with pytest.raises(LumpbeamError, match=r'valid tip poses, need a longer record \(dropped'):
        _record(z=z)
