"""``lumpbeam analyze BAG``: identification of a recorded drop test (SPEC section 5)."""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any, TextIO

from lumpbeam_ros.bagio import BagReader, read_load_events, read_tip_poses
from lumpbeam_ros.cli.output import write_json
from lumpbeam_ros.errors import BagError, LumpbeamError
from lumpbeam_ros.ident.config import load_identifier_config
from lumpbeam_ros.ident.identify import identify
from lumpbeam_ros.ident.result import Identification
from lumpbeam_ros.ident.samples import LoadReadings, PoseWindow, clean_loads, clean_window
from lumpbeam_ros.model.parameters import load_beam_config

POSE_TOPIC = '/tip_pose'
LOAD_TOPIC = '/tip_load'
BASE_FRAME = 'beam_base'
#: A bag with more poses than this shows a progress bar even when stderr is not a TTY.
LONG_BAG_POSES = 200_000

#: SPEC section 5's keys, each also with ``_std``.
SPEC_KEYS = (
    'natural_frequency_hz',
    'damped_frequency_hz',
    'damping_ratio',
    'stiffness_total_nm_per_rad',
    'stiffness_vertical_n_per_m',
    'damping_total',
)


class Progress:
    """A one-line progress bar on a stream, drawn only when it is a TTY or the job is long.

    Args:
        total: Units of work expected.
        label: What is being done.
        stream: Where to draw (default ``sys.stderr``).
        width: Characters of the bar.
    """

    def __init__(self, total: int, label: str, stream: TextIO | None = None, width: int = 30):
        self.stream = stream or sys.stderr
        self.total = max(int(total), 1)
        self.label = label
        self.width = width
        self.done = 0
        self._shown = -1
        self.enabled = self.stream.isatty() or total > LONG_BAG_POSES

    def tick(self, units: int = 1) -> None:
        """Counts ``units`` of work; redraws at each whole per cent."""
        self.done += units
        percent = min(100, 100 * self.done // self.total)
        if self.enabled and percent != self._shown:
            self._shown = percent
            filled = self.width * percent // 100
            bar = '#' * filled + '.' * (self.width - filled)
            self.stream.write(f'\r{self.label} [{bar}] {percent:3d}%')
            self.stream.flush()

    def close(self) -> None:
        """Ends the line."""
        if self.enabled and self._shown >= 0:
            self.stream.write('\n')
            self.stream.flush()


class _CountingReader(BagReader):
    """A bag reader that ticks a progress bar per message it deserializes."""

    progress: Progress | None = None

    def messages(self, topic: str, msgtype: str) -> Iterator[tuple[int, Any]]:
        for item in super().messages(topic, msgtype):
            if self.progress is not None:
                self.progress.tick()
            yield item


def read_window(bag: str | Path) -> PoseWindow:
    """Reads ``/tip_pose`` (and ``/tip_load`` when present) into a cleaned window.

    Args:
        bag: The bag folder.

    Returns:
        The poses in ``beam_base`` with the load readings.

    Raises:
        BagError: Not a bag, no or an empty ``/tip_pose``, poses in another frame.
    """
    reader = _CountingReader(bag)
    if POSE_TOPIC not in reader.topics:
        have = ', '.join(sorted(reader.topics)) or 'no topics'
        raise BagError(f'{bag}: no {POSE_TOPIC} in the bag (it has {have})')
    reader.progress = Progress(reader.topics[POSE_TOPIC].count, f'reading {POSE_TOPIC}')
    try:
        poses = read_tip_poses(reader, POSE_TOPIC)
    finally:
        reader.progress.close()
        reader.progress = None
    if poses.t.size == 0:
        raise BagError(f'{bag}: {POSE_TOPIC} holds no messages')
    if poses.frame_id != BASE_FRAME:
        raise BagError(
            f'{bag}: {POSE_TOPIC} is in frame {poses.frame_id!r}, expected {BASE_FRAME!r}'
        )
    loads = LoadReadings()
    if LOAD_TOPIC in reader.topics:
        series = read_load_events(reader, LOAD_TOPIC)
        loads = clean_loads(series.t, series.kg)
    return clean_window(poses.t, poses.z, poses.pitch, loads)


def result_json(result: Identification) -> dict[str, Any]:
    """The JSON of SPEC section 5 (its keys first), then every other figure."""
    data = result.as_dict()
    head = {key: data[key] for key in SPEC_KEYS}
    head.update({f'{key}_std': data[f'{key}_std'] for key in SPEC_KEYS})
    head['release_time_s'] = data['release_time_s']
    head['static_deflection_m'] = data['static_deflection_m']
    return {**head, **{k: v for k, v in data.items() if k not in head}}


def run(args: argparse.Namespace) -> int:
    """Reads the bag, identifies the whole record, prints a summary, writes JSON and plots."""
    beam, _ = load_beam_config(args.config)
    config = load_identifier_config(args.identifier_config)
    window = read_window(args.bag)
    # The whole record is one window: the fit may run to its end.
    config = replace(config, max_fit_s=math.inf)
    try:
        result = identify(window, beam, config, strict=True)
    except LumpbeamError as exc:
        raise LumpbeamError(f'{args.bag}: {exc}') from None
    print(f'{args.bag}: {len(window)} poses over {window.end_s - window.start_s:.2f} s')
    print(result.summary())
    if args.json:
        write_json(args.json, result_json(result))
    if args.plots:
        from lumpbeam_ros.plots.analysis import write_analysis_plots

        for path in write_analysis_plots(window, result, Path(args.plots)):
            print(f'wrote {path}')
    return 0 if result.ok else 1
