"""The measured record a diagnosis works on: tip poses and the load schedule that drove them.

Not the recording of live topics into a bag: that is ``lumpbeam record``
(:mod:`lumpbeam_ros.apps.cli.record`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from lumpbeam_ros.base.errors import BagError, LumpbeamError
from lumpbeam_ros.base.interface import BASE_FRAME
from lumpbeam_ros.core.bagio import TipSeries, read_load_events, read_tip_poses
from lumpbeam_ros.core.bagio.tipseries import HoldsTipSeries, SampleCounts, clean_tip_series
from lumpbeam_ros.core.model.trajectory import TipTrajectory

#: Fewest poses after the last load change: two seconds at 180 Hz (six periods of the beam).
MIN_SAMPLES_AFTER_EVENT = 360

#: A pause between poses longer than this many median periods is a tracking loss.
TRACKING_LOSS_PERIODS = 1.5

#: A pause or jump of the pose stamps longer than this (s) splits the record: the stretches
#: do not belong to one experiment, and simulating across a jump of 1e6 s would take memory
#: in proportion to it.
MAX_GAP_S = 1.0

#: A stretch of poses shorter than this between two losses joins the stretch after it: a
#: tracker that holds the target for a few frames has not settled on a new solution.
MIN_TRACKED_SAMPLES = 20


@dataclass(frozen=True)
class Record(HoldsTipSeries):
    """Tip poses in ``beam_base`` and the ``/tip_load`` schedule (doc/interfaces.md).

    Attributes:
        poses: The tip series, stamps increasing.
        initial_load_kg: The load hanging at the start; the beam is at rest with it.
        load_events: ``(time, kg)`` load changes after the start, in time order.
        notes: What was dropped or trimmed from the poses given (bad or repeated samples,
            stamp jumps), one line each, for the user.
        counts: The poses given, kept and dropped (before the stamp jumps' trim).
    """

    poses: TipSeries
    initial_load_kg: float
    load_events: tuple[tuple[float, float], ...]
    notes: tuple[str, ...] = ()
    counts: SampleCounts = field(default_factory=SampleCounts)

    @property
    def event_time_s(self) -> float:
        """The time of the first load change (the drop of a drop test)."""
        return self.load_events[0][0]

    @property
    def rate_hz(self) -> float:
        """The median pose rate, Hz."""
        return float(1.0 / np.median(np.diff(self.t)))

    def tracked_segments(self) -> np.ndarray:
        """Which tracked stretch each pose belongs to (see :func:`tracked_segments`)."""
        return tracked_segments(self.t)


def tracked_segments(t: np.ndarray) -> np.ndarray:
    """Labels the stretches of poses between tracking losses, 0 for the first.

    A camera tracker that loses its target (frames missing from the stamps) may settle on
    a slightly different pose solution when it finds it again: a constant bias per stretch
    (tens of micrometres, more than its noise), which no beam model can predict.

    Args:
        t: Increasing stamps, s.

    Returns:
        One integer label per stamp, non-decreasing, 0 up to the first loss.
    """
    t = np.asarray(t, dtype=float)
    if t.size < 2:
        return np.zeros(t.size, dtype=int)
    step = np.diff(t)
    starts = [0, *(np.flatnonzero(step > TRACKING_LOSS_PERIODS * np.median(step)) + 1)]
    kept: list[int] = []
    pending: int | None = None
    for a, b in zip(starts, [*starts[1:], t.size], strict=True):
        pending = a if pending is None else pending
        if b - a >= MIN_TRACKED_SAMPLES:
            kept.append(pending)  # a short stretch before it joins this one
            pending = None
    kept = kept or [0]  # a short last stretch stays with the one before
    kept[0] = 0
    labels = np.zeros(t.size, dtype=int)
    for label, start in enumerate(kept[1:], start=1):
        labels[start:] = label
    return labels


def make_record(
    t: np.ndarray,
    z: np.ndarray,
    pitch: np.ndarray,
    initial_load_kg: float,
    load_events: list[tuple[float, float]] | tuple[tuple[float, float], ...],
    source: str = 'record',
) -> Record:
    """Checks and assembles a record from pose arrays (:func:`record_from_series`).

    Args:
        t: Pose stamps, s.
        z: Vertical tip positions, m.
        pitch: Tip slopes, rad.
        initial_load_kg: Load at the start, kg.
        load_events: ``(time, kg)`` load changes; at least one must fall inside the poses.
        source: Name for error messages (a bag path).

    Returns:
        The record (see :func:`record_from_series`).

    Raises:
        LumpbeamError: As :func:`record_from_series`.
    """
    t, z, pitch = (np.asarray(a, dtype=float).ravel() for a in (t, z, pitch))
    if not t.size == z.size == pitch.size:
        raise LumpbeamError(f'{source}: pose arrays differ in length')
    return record_from_series(
        TipSeries.vertical(t, z, pitch), initial_load_kg, load_events, source
    )


def record_from_series(
    poses: TipSeries,
    initial_load_kg: float,
    load_events: list[tuple[float, float]] | tuple[tuple[float, float], ...],
    source: str = 'record',
    *,
    dropped: SampleCounts | None = None,
) -> Record:
    """Checks and assembles a record; non-finite and repeated poses are dropped and counted.

    Args:
        poses: The tip series (``x`` is carried along, not checked).
        initial_load_kg: Load at the start, kg.
        load_events: ``(time, kg)`` load changes; at least one must fall inside the poses.
        source: Name for error messages (a bag path).
        dropped: What was dropped before ``poses`` (a live buffer's counts of them).

    Returns:
        The record, sorted by time, with events before the first pose folded into the
        initial load and events after the last pose dropped.

    Raises:
        LumpbeamError: A negative or non-finite load, no load change inside the record, or
            fewer than ``MIN_SAMPLES_AFTER_EVENT`` poses after it; the message says what
            was dropped.
    """
    poses, cleaned = clean_tip_series(poses)
    counts = cleaned if dropped is None else dropped.then(cleaned)
    poses, split = _stretch_with_event(poses, load_events)
    notes = tuple(note for note in (counts.note(), split) if note)
    why = f' ({"; ".join(notes)})' if notes else ''
    t = poses.t
    if t.size < MIN_SAMPLES_AFTER_EVENT:
        raise LumpbeamError(f'{source}: {t.size} valid tip poses, need a longer record{why}')
    load = float(initial_load_kg)
    events: list[tuple[float, float]] = []
    for time, kg in sorted((float(a), float(b)) for a, b in load_events):
        if not (np.isfinite(time) and np.isfinite(kg)) or kg < 0.0:
            raise LumpbeamError(f'{source}: tip load {kg!r} kg at {time!r} s is not valid')
        if time <= t[0]:
            load = kg
        elif time < t[-1] and kg != (events[-1][1] if events else load):
            events.append((time, kg))
    if not np.isfinite(load) or load < 0.0:
        raise LumpbeamError(f'{source}: initial tip load {load!r} kg is not valid')
    if not events:
        raise LumpbeamError(
            f'{source}: the tip load never changes during the poses; '
            'a diagnosis needs a load event (a drop) to compare against'
        )
    after = int(np.count_nonzero(t > events[-1][0]))
    if after < MIN_SAMPLES_AFTER_EVENT:
        raise LumpbeamError(
            f'{source}: {after} poses after the last load change at {events[-1][0]:.3f} s, '
            f'need at least {MIN_SAMPLES_AFTER_EVENT}{why}'
        )
    return Record(poses, load, tuple(events), notes, counts)


def _stretch_with_event(
    poses: TipSeries,
    load_events: list[tuple[float, float]] | tuple[tuple[float, float], ...],
) -> tuple[TipSeries, str]:
    """The stretch of poses a diagnosis can use when the stamps pause or jump.

    Increasing stamps are split at pauses over ``MAX_GAP_S``; the first stretch that holds
    a load event is kept (else the longest).

    Returns:
        The kept poses and what was dropped (``''``: nothing).
    """
    t = poses.t
    gaps = np.flatnonzero(np.diff(t) > MAX_GAP_S)
    if gaps.size == 0:
        return poses, ''
    bounds = [0, *(gaps + 1).tolist(), t.size]
    stretches = list(zip(bounds[:-1], bounds[1:], strict=True))
    times = [float(time) for time, _ in load_events]
    holding = [(a, b) for a, b in stretches if any(t[a] < x < t[b - 1] for x in times)]
    a, b = holding[0] if holding else max(stretches, key=lambda ab: ab[1] - ab[0])
    jumps = ', '.join(f'by {t[g + 1] - t[g]:+.6g} s after {t[g]:.3f} s' for g in gaps)
    note = (
        f'/tip_pose stamps jump {jumps}: kept {t[a]:.3f} to {t[b - 1]:.3f} s ({b - a} poses), '
        f'dropped {t.size - (b - a)}'
    )
    return poses.select(slice(a, b)), note


def record_from_trajectory(
    trajectory: TipTrajectory, load_events: list[tuple[float, float]], initial_load_kg: float
) -> Record:
    """A record from a simulated (or synthetic) trajectory.

    Args:
        trajectory: Tip poses (its load and angles are not kept: the events give the load).
        load_events: ``(time, kg)`` load changes.
        initial_load_kg: Load at the start.

    Returns:
        The record.
    """
    poses = TipSeries(
        trajectory.t, trajectory.x, trajectory.z, trajectory.pitch, frame_id=trajectory.frame_id
    )
    return record_from_series(poses, initial_load_kg, load_events, 'trajectory')


def read_record(bag: str | Path) -> Record:
    """Reads ``/tip_pose`` and ``/tip_load`` from a bag.

    The first ``/tip_load`` sample gives the initial load, its changes the events
    (``read_load_events(bag).changes()``).

    Args:
        bag: The bag folder.

    Returns:
        The record.

    Raises:
        BagError: The bag is unreadable, a topic is missing or empty, the poses are not in
            ``beam_base``, or the record holds no usable load change.
    """
    poses = read_tip_poses(bag)
    if poses.frame_id not in (BASE_FRAME, ''):
        raise BagError(f'{bag}: /tip_pose is in frame {poses.frame_id!r}, expected beam_base')
    loads = read_load_events(bag).changes()
    if loads.t.size == 0:
        raise BagError(f'{bag}: /tip_load holds no message')
    events = list(zip(loads.t[1:].tolist(), loads.kg[1:].tolist(), strict=True))
    try:
        return record_from_series(poses, float(loads.kg[0]), events, str(bag))
    except LumpbeamError as exc:
        raise BagError(str(exc)) from None
