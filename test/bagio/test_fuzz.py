"""Random damage to a bag the product wrote, through every path that reads bags.

Each case damages a copy of one synthetic drop test's ``.mcap`` (bytes overwritten, inserted,
deleted, flipped, or the file cut short, one to three times, at random offsets and lengths)
from a seed of its own, so a failure names the seed that reproduces it. What must hold:

- no exception but a one-line :class:`~lumpbeam_ros.errors.LumpbeamError` (``BagError``);
- every message read (as ``lumpbeam play``, ``view``, ``analyze`` read them) is one the
  bag held, byte for byte, and every one not read is counted against its topic;
- ``lumpbeam doctor`` finds every damaged file, and a repaired bag is clean and holds only
  messages the bag held;
- an identification at level OK agrees with the clean bag's.

``make test`` runs :data:`CASES` cases (``LUMPBEAM_FUZZ_CASES`` sets it: ``make fuzz`` runs
thousands); repair and analyze run on every eighth case, diagnose on every two hundredth.
"""

from __future__ import annotations

import os
import shutil
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from lumpbeam_lab.doctor import examine_bag
from lumpbeam_ros.bagio import BagReader, repair_bag
from lumpbeam_ros.diagnose.measurement import read_record
from lumpbeam_ros.diagnose.workflow import diagnose
from lumpbeam_ros.errors import LumpbeamError
from lumpbeam_ros.ident.bag_analysis import analyze_bag
from lumpbeam_ros.ident.identification import Status
from lumpbeam_ros.ident.settings import IdentifierConfig
from lumpbeam_ros.model.parameters import load_beam_config
from lumpbeam_ros.synthetic.drop_test import SynthOptions, write_drop_test_bag

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
