"""Bag I/O benchmarks: the recorder's write path at camera rate, reading poses, the player.

- ``bag_write_1mp_180fps``: 1024 x 1024 mono8 images (CDR-serialized ``sensor_msgs/Image``,
  as the recorder receives them) plus one ``PoseStamped`` per frame, written through
  :class:`~lumpbeam_ros.core.bagio.BagWriter` with its periodic flush. Baseline: a plain buffered
  file write of the same bytes, in the same run. The recorder keeps up with a 180 fps camera
  when the sustained rate exceeds ``180 * frame size`` (``headroom`` > 1). This measures the
  writer path in-process: a full 180 MB/s stream through DDS loopback on a 2-core machine
  measures the middleware's copy cost more than the recorder's.
- ``bag_read_tip_poses``: a 180 Hz pose topic read into arrays by
  :func:`~lumpbeam_ros.core.bagio.read_tip_poses`, whose CDR decoding is the vectorized fast path
  (:mod:`~lumpbeam_ros.core.bagio.fastscan`). Baseline: the same reader with the library's
  per-message decoding (rosbags, ``fast=False``), in the same run. The details give the
  reader alone (messages read through mcap, not decoded), which both sides share.
- ``play_timing_p99``: the player's lateness (publish time minus schedule), 99th percentile,
  on a 180 Hz pose bag at real time. Baseline: a bare ``sleep``-until loop on the same
  schedule without publishing, i.e. the scheduler's own jitter.
"""

from __future__ import annotations

import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

from lumpbeam_lab.bench.bench_result import BenchResult, best_time
from lumpbeam_ros.base.interface import (
    BASE_FRAME,
    CAMERA_FRAME,
    IMAGE,
    IMAGE_TYPE,
    POSE_STAMPED,
    TIP_POSE,
)
from lumpbeam_ros.core.bagio import BagReader, BagWriter, convert, read_tip_poses
from lumpbeam_ros.core.bagio.typestore import serialize
from lumpbeam_ros.nodes.ros_domain import claim_domain_id

FPS = 180.0
SIDE = 1024


def _frames(count: int) -> tuple[list[bytes], list[bytes]]:
    rng = np.random.default_rng(0)
    pixels = rng.integers(0, 256, (SIDE, SIDE), dtype=np.uint8)
    images, poses = [], []
    for i in range(count):
        ns = round(i / FPS * 1e9)
        images.append(serialize(convert.image(ns, pixels, CAMERA_FRAME)))
        poses.append(serialize(convert.pose_stamped(ns, 2.3, -0.01, 0.01, BASE_FRAME)))
    return images, poses


def _bag_write(folder: Path, images: list[bytes], poses: list[bytes]) -> float:
    start = time.perf_counter()
    with BagWriter(folder / 'bag') as bag:
        bag.add_topic(IMAGE, IMAGE_TYPE)
        bag.add_topic(TIP_POSE, POSE_STAMPED)
        for i, (image, pose) in enumerate(zip(images, poses, strict=True)):
            ns = round(i / FPS * 1e9)
            bag.write_raw(IMAGE, ns, image)
            bag.write_raw(TIP_POSE, ns, pose)
    return time.perf_counter() - start


def _raw_write(folder: Path, images: list[bytes], poses: list[bytes]) -> float:
    start = time.perf_counter()
    with (folder / 'raw.bin').open('wb') as f:
        for image, pose in zip(images, poses, strict=True):
            f.write(image)
            f.write(pose)
    return time.perf_counter() - start


def _write_benchmark(quick: bool) -> BenchResult:
    count = 36 if quick else 540  # 0.2 s or 3 s of camera
    images, poses = _frames(count)
    total = sum(map(len, images)) + sum(map(len, poses))
    best_bag, best_raw = float('inf'), float('inf')
    for _ in range(1 if quick else 3):
        with tempfile.TemporaryDirectory(prefix='lumpbeam-bench-') as tmp:
            best_raw = min(best_raw, _raw_write(Path(tmp), images, poses))
            best_bag = min(best_bag, _bag_write(Path(tmp), images, poses))
            written = BagReader(Path(tmp) / 'bag').info.message_count
    bag_mbps, raw_mbps = total / best_bag / 1e6, total / best_raw / 1e6
    needed = FPS * total / count / 1e6
    return BenchResult(
        name='bag_write_1mp_180fps',
        value=bag_mbps,
        unit='MB/s',
        baseline='plain file write of the same bytes',
        baseline_value=raw_mbps,
        ratio=bag_mbps / raw_mbps,
        details={
            'frames': count,
            'messages_written': written,
            'dropped': 2 * count - written,
            'needed_MBps_at_180fps': needed,
            'headroom_vs_180fps': bag_mbps / needed,
            'sustained_fps': count / best_bag,
            'path': 'in-process writer (no DDS)',
        },
    )


def _read_benchmark(quick: bool) -> BenchResult:
    count = int((30.0 if quick else 120.0) * FPS)
    with tempfile.TemporaryDirectory(prefix='lumpbeam-bench-') as tmp:
        bag = Path(tmp) / 'poses'
        with BagWriter(bag) as writer:
            for i in range(count):
                writer.write_pose(TIP_POSE, 1000.0 + i / FPS, 2.3, -0.01 * np.sin(i / 9.0), 0.0)
        fast_s, fast = best_time(lambda: read_tip_poses(bag))
        general_s, general = best_time(lambda: read_tip_poses(bag, fast=False))
        reader_s, read = best_time(lambda: sum(1 for _ in BagReader(bag).iter_raw([TIP_POSE])))
    agree = bool(np.array_equal(fast.t, general.t) and np.array_equal(fast.z, general.z))
    return BenchResult(
        name='bag_read_tip_poses',
        value=count / fast_s,
        unit='pose msgs/s',
        baseline='the same reader, per-message CDR decoding (rosbags)',
        baseline_value=count / general_s,
        ratio=general_s / fast_s,
        details={
            'poses': count,
            'reader_only_msgs_per_s': read / reader_s,
            'reader_share_of_fast_path': reader_s / fast_s,
            'fast_equals_general': agree,
        },
    )


def _sleep_until_lateness(schedule: np.ndarray) -> np.ndarray:
    start = time.perf_counter()
    late = np.empty(schedule.size)
    for i, due in enumerate(schedule):
        delay = start + due - time.perf_counter()
        if delay > 0.0:
            time.sleep(delay)
        late[i] = time.perf_counter() - (start + due)
    return late


def _play_benchmark(quick: bool) -> BenchResult:
    import rclpy
    from rclpy.context import Context

    from lumpbeam_ros.nodes.player import Player

    seconds = 0.5 if quick else 3.0
    t = np.arange(0.0, seconds, 1.0 / FPS)
    tmp = Path(tempfile.mkdtemp(prefix='lumpbeam-bench-'))
    context = Context()
    # A private domain: the benchmark must not publish into a user's graph or another run's.
    claim = claim_domain_id()
    rclpy.init(context=context, domain_id=claim.domain_id)
    try:
        with BagWriter(tmp / 'poses') as bag:
            for ti in t:
                bag.write_pose(TIP_POSE, 1000.0 + ti, 2.3, -0.01, 0.0)
        player = Player(BagReader(tmp / 'poses'), context=context)
        stats = player.play()
        player.destroy_node()
    finally:
        rclpy.shutdown(context=context)
        claim.release()
        shutil.rmtree(tmp, ignore_errors=True)
    baseline = _sleep_until_lateness(t)
    p99 = stats.lateness_percentile_ms(99)
    base_p99 = float(np.percentile(baseline, 99) * 1e3)
    return BenchResult(
        name='play_timing_p99',
        value=p99,
        unit='ms',
        baseline='sleep-until loop, no publishing',
        baseline_value=base_p99,
        ratio=base_p99 / p99 if p99 > 0 else float('inf'),
        details={
            'messages': int(t.size) * 2,
            'p50_ms': stats.lateness_percentile_ms(50),
            'max_ms': stats.lateness_percentile_ms(100),
        },
    )


def run(quick: bool = False) -> list[BenchResult]:
    """Runs the bag I/O benchmarks.

    Args:
        quick: Smaller inputs (for the benchmark's own test).

    Returns:
        The writer throughput, the pose reading and the player timing results.
    """
    return [_write_benchmark(quick), _read_benchmark(quick), _play_benchmark(quick)]
