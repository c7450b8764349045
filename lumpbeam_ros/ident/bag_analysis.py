"""The identification of one recorded drop test, as ``lumpbeam analyze`` runs it (ROS-free).

``lumpbeam analyze``, ``lumpbeam campaign`` and the HTML report all call
:func:`analyze_bag`, so a bag gives the same figures whichever way it is analysed.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from lumpbeam_ros.bagio import BagReader, read_load_events, read_tip_poses
from lumpbeam_ros.bagio.tipseries import LoadSeries
from lumpbeam_ros.errors import BagError, LumpbeamError
from lumpbeam_ros.ident.identification import Identification
from lumpbeam_ros.ident.identify import FitState, identify_from
from lumpbeam_ros.ident.samples import PoseWindow, clean_loads, clean_window
from lumpbeam_ros.ident.segments import keep_release_segment
from lumpbeam_ros.ident.settings import IdentifierConfig
from lumpbeam_ros.interface import BASE_FRAME, TIP_LOAD, TIP_POSE
from lumpbeam_ros.model.parameters import BeamParameters
from lumpbeam_ros.progress import Progress

POSE_TOPIC = TIP_POSE
LOAD_TOPIC = TIP_LOAD

#: The keys scripts rely on (doc/interfaces.md, "lumpbeam analyze"), each also with ``_std``.
CONTRACT_KEYS = (
    'natural_frequency_hz',
    'damped_frequency_hz',
    'damping_ratio',
    'stiffness_total_nm_per_rad',
    'stiffness_vertical_n_per_m',
    'damping_total',
)


class _CountingReader(BagReader):
    """A bag reader that ticks a progress bar per message it deserializes."""

    progress: Progress | None = None

    def messages(self, topic: str, msgtype: str) -> Iterator[tuple[int, Any]]:
        for item in super().messages(topic, msgtype):
            if self.progress is not None:
                self.progress.tick()
            yield item


def read_window(bag: str | Path, show_progress: bool = True) -> PoseWindow:
    """Reads ``/tip_pose`` (and ``/tip_load`` when present) into a cleaned window.

    Args:
        bag: The bag folder.
        show_progress: Draw a progress bar on stderr (on a TTY, or for a long bag).

    Returns:
        The poses in ``beam_base`` with the load readings.

    Raises:
        BagError: Not a bag, no or an empty ``/tip_pose``, poses in another frame.
    """
    reader = _CountingReader(bag)
    if POSE_TOPIC not in reader.topics:
        have = ', '.join(sorted(reader.topics)) or 'no topics'
        raise BagError(f'{bag}: no {POSE_TOPIC} in the bag (it has {have})')
    if show_progress:
        reader.progress = Progress(reader.topics[POSE_TOPIC].count, f'reading {POSE_TOPIC}')
    try:
        poses = read_tip_poses(reader, POSE_TOPIC)
    finally:
        if reader.progress is not None:
            reader.progress.close()
        reader.progress = None
    if poses.t.size == 0:
        raise BagError(f'{bag}: {POSE_TOPIC} holds no messages')
    if poses.frame_id != BASE_FRAME:
        raise BagError(
            f'{bag}: {POSE_TOPIC} is in frame {poses.frame_id!r}, expected {BASE_FRAME!r}'
        )
    loads = LoadSeries()
    if LOAD_TOPIC in reader.topics:
        series = read_load_events(reader, LOAD_TOPIC)
        loads = clean_loads(series.t, series.kg)
    return clean_window(poses.t, poses.z, poses.pitch, loads, x=poses.x)


def result_json(result: Identification) -> dict[str, Any]:
    """The JSON of ``lumpbeam analyze``: the keys scripts rely on first, then every other."""
    data = result.as_dict()
    head = {key: data[key] for key in CONTRACT_KEYS}
    head.update({f'{key}_std': data[f'{key}_std'] for key in CONTRACT_KEYS})
    head['release_time_s'] = data['release_time_s']
    head['static_deflection_m'] = data['static_deflection_m']
    return {**head, **{k: v for k, v in data.items() if k not in head}}


@dataclass(frozen=True)
class BagAnalysis:
    """A bag's drop test identified over its whole record.

    Attributes:
        bag: The bag folder.
        window: The poses analysed.
        result: The identification.
        fit: The fitted decay and cross-checks (``None`` when the identification failed).
        notes: What was dropped from the bag's poses and why (bad or repeated samples,
            stretches cut off by a stamp gap), one line each, for the user to see.
    """

    bag: Path
    window: PoseWindow
    result: Identification
    fit: FitState | None
    notes: tuple[str, ...] = ()


def analyze_bag(
    bag: str | Path,
    beam: BeamParameters,
    config: IdentifierConfig,
    show_progress: bool = True,
) -> BagAnalysis:
    """Identifies frequency, damping and stiffness from a whole bag (B.12, B.20-B.22).

    Args:
        bag: The bag folder, with ``/tip_pose`` and (optionally) ``/tip_load``.
        beam: Supplies L, g and the masses.
        config: Identifier settings; the fit may run to the record's end whatever
            ``max_fit_s`` says, since the whole record is one window.
        show_progress: Draw a progress bar while reading.

    Returns:
        The analysis.

    Raises:
        BagError: Not a bag or no usable ``/tip_pose``.
        LumpbeamError: Too few samples, named with the bag.
    """
    window = read_window(bag, show_progress)
    window, split = keep_release_segment(window, config)
    notes = tuple(note for note in (window.counts.note(), split) if note)
    config = replace(config, max_fit_s=math.inf)
    try:
        result, fit = identify_from(window, beam, config, strict=True)
    except LumpbeamError as exc:
        raise LumpbeamError(f'{bag}: {exc}') from None
    return BagAnalysis(Path(bag), window, result, fit, notes)
