"""Bags for the bagio tests: a stand-in drop test (damped sinusoid, not the beam model)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from lumpbeam_ros.core.bagio import BagWriter

T0 = 1_700_000_000.0  # an epoch offset, as a real recording has


def stand_in_drop(rate_hz: float = 180.0, duration: float = 4.0) -> dict[str, np.ndarray]:
    """Tip samples: -0.05 m sag until t = 2 s, then a 3.1 Hz damped oscillation about -0.01 m."""
    t = np.arange(0.0, duration, 1.0 / rate_hz)
    after = np.clip(t - 2.0, 0.0, None)
    z = np.where(
        t < 2.0,
        -0.05,
        -0.01 - 0.04 * np.exp(-0.03 * 2 * np.pi * 3.1 * after) * np.cos(2 * np.pi * 3.1 * after),
    )
    return {'t': t, 'x': 2.31 - 0.1 * z**2, 'z': z, 'pitch': -1.5 * z / 2.31}


def write_drop_bag(path: Path, images: int = 0, flush_every: int = 36) -> dict:
    """Writes poses, the load and optionally small mono8 images; returns the samples.

    A flush every ``flush_every`` samples (0.2 s) cuts the file into 20 chunks, as a live
    recording's periodic flushes do.
    """
    s = stand_in_drop()
    with BagWriter(path) as bag:
        for i, t in enumerate(s['t']):
            bag.write_pose('/tip_pose', T0 + t, s['x'][i], s['z'][i], s['pitch'][i])
            if i % 18 == 0:
                bag.write_float('/tip_load', T0 + t, 4.5 if t < 2.0 else 0.0)
            if i < images:
                bag.write_image('/camera/image_raw', T0 + t, np.full((8, 10), i, np.uint8))
            if i % flush_every == flush_every - 1:
                bag.flush()
    return s


#: The fields of a /tip_pose message a stream mutation may spoil.
POSE_FIELDS = ('x', 'y', 'z', 'qx', 'qy', 'qz', 'qw')
STREAM_KINDS = ('bad_value', 'shuffle', 'duplicate', 'gap', 'jump', 'bad_load', 'load_order')
NS = 1_000_000_000


def mutate_stream(poses: list, loads: list, seed: int) -> tuple[list, list]:
    """One to four random stream faults, reproducible from ``seed``.

    ``poses`` rows are ``[stamp_ns, x, y, z, qx, qy, qz, qw]``, ``loads`` rows
    ``[stamp_ns, kg]``; both are copied.
    """
    rng = np.random.default_rng(seed)
    poses = [list(row) for row in poses]
    loads = [list(row) for row in loads]
    for _ in range(int(rng.integers(1, 5))):
        kind = STREAM_KINDS[int(rng.integers(len(STREAM_KINDS)))]
        n = len(poses)
        at = int(rng.integers(n))
        span = int(rng.integers(1, max(2, n // 4)))
        if kind == 'bad_value':
            value = (np.nan, np.inf, -np.inf, 1e308)[int(rng.integers(4))]
            column = 1 + int(rng.integers(len(POSE_FIELDS)))
            for i in rng.choice(n, size=min(n, int(rng.integers(1, 60))), replace=False):
                poses[int(i)][column] = value
        elif kind == 'shuffle':
            block = poses[at : at + span]
            order = rng.permutation(len(block))
            poses[at : at + span] = [block[i] for i in order]
        elif kind == 'duplicate':
            poses[at:at] = [list(row) for row in poses[at : at + span]]
        elif kind == 'gap':
            del poses[at : at + span]
        elif kind == 'jump':
            # Forward by up to 1e6 s or back, from one pose on (stamps stay >= 0).
            shift = int(float(rng.choice([-1.0, 1.0])) * 10 ** rng.uniform(-3, 6) * NS)
            for row in poses[at:]:
                row[0] = max(0, row[0] + shift)
        elif kind == 'bad_load' and loads:
            loads[int(rng.integers(len(loads)))][1] = (np.nan, np.inf, -1.0)[int(rng.integers(3))]
        elif kind == 'load_order' and loads:
            loads[int(rng.integers(len(loads)))][0] = int(rng.integers(0, 2 * poses[-1][0] + 1))
        if not poses:
            break
    return poses, loads


def stream_rows(path: Path) -> tuple[list, list]:
    """A bag's /tip_pose and /tip_load as the rows :func:`mutate_stream` takes.

    Poses are ``[stamp_ns, x, y, z, qx, qy, qz, qw]``, loads ``[log_time_ns, kg]``.
    """
    from lumpbeam_ros.base.interface import TIP_LOAD, TIP_POSE
    from lumpbeam_ros.core.bagio import BagReader
    from lumpbeam_ros.core.bagio.typestore import deserialize

    reader = BagReader(path)
    poses, loads = [], []
    for raw in reader.iter_raw([TIP_POSE, TIP_LOAD]):
        msg = deserialize(raw.data, reader.topics[raw.topic].msgtype)
        if raw.topic == TIP_POSE:
            p, q = msg.pose.position, msg.pose.orientation
            stamp = msg.header.stamp.sec * NS + msg.header.stamp.nanosec
            poses.append([stamp, p.x, p.y, p.z, q.x, q.y, q.z, q.w])
        else:
            loads.append([raw.log_time_ns, msg.data])
    return poses, loads
