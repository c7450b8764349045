"""Random damage to a bag the product wrote, through every path that reads bags.

Each case damages a copy of one synthetic drop test's ``.mcap`` (bytes overwritten, inserted,
deleted, flipped, or the file cut short, one to three times, at random offsets and lengths)
from a seed of its own, so a failure names the seed that reproduces it. What must hold:

- no exception but a one-line :class:`~lumpbeam_ros.base.errors.LumpbeamError` (``BagError``);
- every message read (as ``lumpbeam play``, ``view``, ``analyze`` read them) is one the
  bag held, byte for byte, and every one not read is counted against its topic;
- ``lumpbeam doctor`` finds every damaged file, and a repaired bag is clean and holds only
  messages the bag held;
- an identification at level OK agrees with the clean bag's.

The same damage goes to a short filmed drop test through ``lumpbeam track``: every frame
gives a pose or a counted loss, every pose is the clean bag's at that stamp, a failed track
leaves no OUT.

A second family of cases keeps the bag whole and spoils its streams instead
(:func:`bagio.helpers.mutate_stream`): ``/tip_pose`` stamps shuffled, duplicated, cut out or
jumping by up to 1e6 s either way, NaN, inf or 1e308 in any field of a pose, NaN, inf or a
negative mass on ``/tip_load`` and its readings out of order, through ``analyze`` and
``diagnose``: every pose given is kept or counted as dropped, the kept ones are finite and
increasing, an estimate at level OK is the clean one (and never comes from a window with more
than 5 % dropped).

``make test`` runs :data:`CASES` cases (``LUMPBEAM_FUZZ_CASES`` sets it: ``make fuzz`` runs
thousands); repair and analyze run on every eighth case, track on every sixteenth, the
streams on every fifth, diagnose on every two hundredth (of either family).
"""

from __future__ import annotations

import os
import shutil
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from core.bagio.helpers import NS, mutate_stream, stream_rows
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.bagio import BagReader, repair_bag
from lumpbeam_ros.core.bagio.check import examine_bag
from lumpbeam_ros.core.diagnose.measurement import read_record
from lumpbeam_ros.core.diagnose.workflow import diagnose
from lumpbeam_ros.core.ident.bag_analysis import analyze_bag
from lumpbeam_ros.core.ident.identification import Status
from lumpbeam_ros.core.ident.settings import IdentifierConfig
from lumpbeam_ros.core.model.parameters import load_beam_config
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, write_drop_test_bag

CASES = int(os.environ.get('LUMPBEAM_FUZZ_CASES', '200'))
KINDS = ('overwrite', 'insert', 'delete', 'flip', 'truncate')


def damage(data: bytes, seed: int) -> bytes:
    """One to three random damages of ``data``, reproducible from ``seed``."""
    rng = np.random.default_rng(seed)
    out = bytearray(data)
    for _ in range(int(rng.integers(1, 4))):
        if not out:
            break
        kind = KINDS[int(rng.integers(len(KINDS)))]
        at = int(rng.integers(len(out)))
        n = int(rng.integers(1, 400))
        if kind == 'overwrite':
            out[at : at + n] = rng.bytes(len(out[at : at + n]))
        elif kind == 'insert':
            out[at:at] = rng.bytes(n)
        elif kind == 'delete':
            del out[at : at + n]
        elif kind == 'flip':
            out[at] ^= 1 << int(rng.integers(8))
        else:
            del out[at:]
    return bytes(out)


@pytest.fixture(scope='module')
def clean(tmp_path_factory):
    """The clean bag, its messages, and its identification."""
    path = tmp_path_factory.mktemp('fuzz') / 'drop'
    beam, drop = load_beam_config()
    write_drop_test_bag(path, beam, drop, SynthOptions(duration_s=5.0))
    reader = BagReader(path)
    messages = Counter((r.topic, r.log_time_ns, bytes(r.data)) for r in reader.iter_raw())
    analysis = analyze_bag(path, beam, IdentifierConfig(), show_progress=False)
    assert analysis.result.status == Status.OK
    return path, messages, analysis.result, beam


def _damaged(clean_path: Path, folder: Path, seed: int) -> tuple[Path, bool]:
    bag = folder / f'case{seed}'
    shutil.copytree(clean_path, bag)
    (file,) = bag.glob('*.mcap')
    original = file.read_bytes()
    data = damage(original, seed)
    file.write_bytes(data)
    return bag, data != original


def _one_line(exc: LumpbeamError, seed: int) -> None:
    assert str(exc) and '\n' not in str(exc), f'seed {seed}: {exc!r}'


def _assert_held(messages: Counter, clean_messages: Counter, seed: int) -> None:
    extra = messages - clean_messages
    assert not extra, f'seed {seed}: {sum(extra.values())} messages the bag never held'


def test_readers_and_doctor(clean, tmp_path):
    clean_path, clean_messages, _, _ = clean
    for seed in range(CASES):
        bag, changed = _damaged(clean_path, tmp_path, seed)
        try:
            reader = BagReader(bag)
            read = Counter((r.topic, r.log_time_ns, bytes(r.data)) for r in reader.iter_raw())
        except LumpbeamError as exc:
            _one_line(exc, seed)
        else:
            _assert_held(read, clean_messages, seed)
            per_topic = Counter(topic for topic, _, _ in read.elements())
            for topic, entry in reader.topics.items():
                lost = reader.lost.get(topic, 0)
                assert per_topic[topic] + lost == entry.count, f'seed {seed}: {topic}'
        try:
            problems = examine_bag(bag)
        except LumpbeamError as exc:
            _one_line(exc, seed)
        else:
            assert problems or not changed, f'seed {seed}: doctor called a damaged bag clean'
        shutil.rmtree(bag)


def test_repair_and_analyze(clean, tmp_path):
    clean_path, clean_messages, clean_result, beam = clean
    clean_hz = clean_result.estimates.natural_frequency_hz.value
    for seed in range(0, CASES, 8):
        bag, _ = _damaged(clean_path, tmp_path, seed)
        out = tmp_path / f'repaired{seed}'
        try:
            repair_bag(bag, out)
        except LumpbeamError as exc:
            _one_line(exc, seed)
            assert not out.exists(), f'seed {seed}: a failed repair left {out}'
        else:
            copied = Counter(
                (r.topic, r.log_time_ns, bytes(r.data)) for r in BagReader(out).iter_raw()
            )
            _assert_held(copied, clean_messages, seed)
            assert examine_bag(out) == [], f'seed {seed}: the repaired bag is not clean'
            shutil.rmtree(out)
        try:
            result = analyze_bag(bag, beam, IdentifierConfig(), show_progress=False).result
        except LumpbeamError as exc:
            _one_line(exc, seed)
        else:
            if result.status == Status.OK:
                hz = result.estimates.natural_frequency_hz.value
                assert abs(hz - clean_hz) < 0.05 * clean_hz, f'seed {seed}: {hz} Hz'
        shutil.rmtree(bag)


def test_diagnose(clean, tmp_path):
    clean_path, _, _, beam = clean
    for seed in range(0, CASES, 200):
        bag, _ = _damaged(clean_path, tmp_path, seed)
        try:
            diagnose(read_record(bag), beam)
        except LumpbeamError as exc:
            _one_line(exc, seed)
        shutil.rmtree(bag)


# -- the streams: stamps out of order, gaps, jumps, duplicates, NaN and inf in every field ----


def _write_stream(path: Path, poses: list, loads: list) -> None:
    """Writes the rows as /tip_pose and /tip_load, logged in the order given."""
    from lumpbeam_ros.base.interface import BASE_FRAME, TIP_LOAD, TIP_POSE
    from lumpbeam_ros.core.bagio import BagWriter
    from lumpbeam_ros.core.bagio.convert import float64, header
    from lumpbeam_ros.core.bagio.typestore import message_class

    point, quaternion, pose, stamped = (
        message_class(f'geometry_msgs/msg/{name}')
        for name in ('Point', 'Quaternion', 'Pose', 'PoseStamped')
    )
    rows = [(row, TIP_POSE) for row in poses] + [(row, TIP_LOAD) for row in loads]
    with BagWriter(path) as bag:
        for log_index, (row, topic) in enumerate(rows):
            log_ns = NS + log_index * 1000
            if topic == TIP_LOAD:
                bag.write_message(topic, float64(row[1]), log_ns)
                continue
            stamp, x, y, z, qx, qy, qz, qw = row
            msg = stamped(
                header=header(int(stamp), BASE_FRAME),
                pose=pose(
                    position=point(x=float(x), y=float(y), z=float(z)),
                    orientation=quaternion(x=float(qx), y=float(qy), z=float(qz), w=float(qw)),
                ),
            )
            bag.write_message(topic, msg, log_ns)


@pytest.fixture(scope='module')
def clean_stream(clean):
    """The clean bag's /tip_pose and /tip_load as rows."""
    return stream_rows(clean[0])


def test_streams_through_analyze(clean, clean_stream, tmp_path):
    """Every pose read is kept or counted as dropped; an OK estimate is the clean one."""
    _, _, clean_result, beam = clean
    clean_hz = clean_result.estimates.natural_frequency_hz.value
    statuses = Counter()
    for seed in range(0, CASES, 5):
        poses, loads = mutate_stream(*clean_stream, seed)
        bag = tmp_path / f'stream{seed}'
        _write_stream(bag, poses, loads)
        try:
            analysis = analyze_bag(bag, beam, IdentifierConfig(), show_progress=False)
        except LumpbeamError as exc:
            _one_line(exc, seed)
            statuses['error'] += 1
        else:
            counts, window = analysis.window.counts, analysis.window
            assert counts.received == len(poses), f'seed {seed}'
            kept = len(window.t)
            assert counts.kept >= kept, f'seed {seed}: {counts}, {kept} kept'
            assert np.all(np.isfinite(window.t)) and np.all(np.diff(window.t) > 0), seed
            assert np.all(np.isfinite(window.z)) and np.all(np.isfinite(window.pitch)), seed
            bad_z = sum(1 for row in poses if not np.isfinite(row[3]))
            assert counts.non_finite >= bad_z, f'seed {seed}'
            if counts.dropped:
                assert any('dropped' in note for note in analysis.notes), f'seed {seed}'
            result = analysis.result
            statuses[result.status.name] += 1
            if result.status == Status.OK:
                assert not counts.untrusted, f'seed {seed}: OK with {counts}'
                hz = result.estimates.natural_frequency_hz.value
                assert abs(hz - clean_hz) < 0.05 * clean_hz, f'seed {seed}: {hz} Hz'
        _diagnose_stream(bag, beam, seed)
        shutil.rmtree(bag)
    print(f'streams through analyze: {dict(statuses)}')


def _diagnose_stream(bag: Path, beam, seed: int) -> None:
    try:
        record = read_record(bag)
    except LumpbeamError as exc:
        _one_line(exc, seed)
        return
    counts = record.counts
    assert counts.kept >= len(record.t) and counts.received >= counts.kept, f'seed {seed}'
    assert np.all(np.isfinite(record.z)) and np.all(np.diff(record.t) > 0), f'seed {seed}'
    if seed % 200:
        return  # a diagnosis takes seconds: make test runs one
    try:
        diagnose(record, beam)
    except LumpbeamError as exc:
        _one_line(exc, seed)


# -- lumpbeam track on damaged image bags -----------------------------------------------------


@pytest.fixture(scope='module')
def filmed(tmp_path_factory):
    """A short filmed drop test (320 x 240, 25 frames a second), and its clean tracking."""
    from lumpbeam_ros.core.synthetic.images import ImageOptions
    from lumpbeam_ros.core.vision.config import load_camera_config

    folder = tmp_path_factory.mktemp('filmed')
    beam, drop = load_beam_config()
    options = SynthOptions(duration_s=2.4, rate_hz=25.0, markers_rate_hz=0.0)
    write_drop_test_bag(folder / 'bag', beam, drop, options, images=ImageOptions(320, 240))
    config = load_camera_config().with_resolution(320, 240)
    clean_poses = _tracked(folder / 'bag', folder / 'clean_out', config)
    assert clean_poses
    return folder / 'bag', config, clean_poses


def _tracked(bag: Path, out: Path, config) -> dict[int, float]:
    """Tracks a bag into OUT; returns OUT's /tip_pose z by stamp (ns)."""
    from lumpbeam_ros.core.bagio import read_tip_poses
    from lumpbeam_ros.core.vision.offline import track_bag

    track_bag(bag, out, config)
    poses = read_tip_poses(out)
    return {round(t * 1e9): float(z) for t, z in zip(poses.t, poses.z, strict=True)}


def test_track_on_damaged_image_bags(filmed, tmp_path):
    """Every frame gives a pose or a counted loss, and so does every damaged message.

    Each pose is one of the clean bag's frames, where the clean tracking has the same pose.
    """
    from lumpbeam_ros.base.interface import IMAGE
    from lumpbeam_ros.core.bagio import read_tip_poses
    from lumpbeam_ros.core.vision.offline import track_bag

    bag_path, config, clean_poses = filmed
    outcomes = Counter()
    for seed in range(0, CASES, 16):
        bag, _ = _damaged(bag_path, tmp_path, seed)
        out = tmp_path / f'tracked{seed}'
        try:
            summary = track_bag(bag, out, config)
        except LumpbeamError as exc:
            _one_line(exc, seed)
            assert not out.exists(), f'seed {seed}: a failed track left {out}'
            outcomes['error'] += 1
        else:
            reader = BagReader(bag)
            read = sum(1 for _ in reader.iter_raw([IMAGE]))
            lost_messages = reader.lost.get(IMAGE, 0)
            assert summary.frames == read, f'seed {seed}: {summary.frames} frames, {read} read'
            assert read + lost_messages == reader.topics[IMAGE].count, f'seed {seed}'
            lost = sum(summary.lost_by_reason.values())
            assert summary.poses + lost == summary.frames, f'seed {seed}: {summary}'
            poses = read_tip_poses(out) if summary.poses else None
            if poses is not None:
                for t, z in zip(poses.t, poses.z, strict=True):
                    stamp = round(t * 1e9)
                    assert stamp in clean_poses, f'seed {seed}: a pose at {t} s'
                    assert abs(z - clean_poses[stamp]) < 1e-4, f'seed {seed}: z at {t} s'
            outcomes['tracked'] += 1
            shutil.rmtree(out)
        shutil.rmtree(bag)
    print(f'track on damaged image bags: {dict(outcomes)}')
