"""The identification of one recorded drop test or arm move, as ``lumpbeam analyze`` runs it.

``lumpbeam analyze``, ``lumpbeam campaign`` and the HTML report all call
:func:`analyze_bag`, so a bag gives the same figures whichever way it is analysed. ROS-free.
Its modes, for a script (e.g. fitting an arm's links to the modes of several bags)::

    analysis = analyze_bag(bag, BeamParameters(), load_identifier_config(), arm_joints=3)
    analysis.rest.angles_rad          # the joints' angles at rest after the move
    [(m.natural_frequency_hz.value, m.natural_frequency_hz.std,
      m.damping_ratio.value, m.damping_ratio.std) for m in analysis.modes]
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from lumpbeam_ros.base.errors import BagError, LumpbeamError
from lumpbeam_ros.base.interface import BASE_FRAME, JOINT_STATES, TIP_IMU, TIP_LOAD, TIP_POSE
from lumpbeam_ros.base.progress import Progress
from lumpbeam_ros.core.bagio import BagReader, read_load_events, read_tip_poses
from lumpbeam_ros.core.bagio.series import JointSeries, read_accelerations, read_joint_states
from lumpbeam_ros.core.bagio.tipseries import LoadSeries
from lumpbeam_ros.core.ident.assembly import FitState
from lumpbeam_ros.core.ident.free_vibration import (
    EventModes,
    FreeVibration,
    Line,
    analyze_record,
    steady_lines,
)
from lumpbeam_ros.core.ident.identification import Identification, IdentifiedMode
from lumpbeam_ros.core.ident.identify import identify_from
from lumpbeam_ros.core.ident.ring_down import (
    JointRest,
    last_ring_down,
    min_rest_s,
    rest_stretches,
    swing_after,
)
from lumpbeam_ros.core.ident.samples import PoseWindow, clean_loads, clean_window
from lumpbeam_ros.core.ident.segments import keep_release_segment
from lumpbeam_ros.core.ident.settings import IdentifierConfig
from lumpbeam_ros.core.model.parameters import BeamParameters

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


def result_json(result: Identification, rest: JointRest | None = None) -> dict[str, Any]:
    """The JSON of ``lumpbeam analyze``: the keys scripts rely on first, then every other.

    Args:
        result: The identification.
        rest: For an arm's bag, where its joints stopped: adds ``joint_angles_rad``.
    """
    data = result.as_dict()
    head = {key: data[key] for key in CONTRACT_KEYS}
    head.update({f'{key}_std': data[f'{key}_std'] for key in CONTRACT_KEYS})
    head['release_time_s'] = data['release_time_s']
    head['static_deflection_m'] = data['static_deflection_m']
    out = {**head, **{k: v for k, v in data.items() if k not in head}}
    if rest is not None:
        out['joint_angles_rad'] = list(rest.angles_rad)
    return out


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
        rest: For an arm's bag, the joints at rest after the last move: when they stopped
            (the start of the free vibration) and at which angles (the configuration the
            modes belong to); ``None`` for a drop test.
        lines: The record's steady lines (``lines`` in JSON).
        events: Its free vibrations, each identified (``events`` in JSON).
        quantity: What ``window`` holds as its z: ``displacement`` (m) or ``acceleration``
            (m/s^2, a ``/tip_imu`` record).
        imu: The ``/tip_imu`` record's own analysis when the bag also has ``/tip_pose``.
    """

    bag: Path
    window: PoseWindow
    result: Identification
    fit: FitState | None
    notes: tuple[str, ...] = ()
    rest: JointRest | None = None
    lines: tuple[Line, ...] = ()
    events: tuple[EventModes, ...] = ()
    quantity: str = 'displacement'
    imu: BagAnalysis | None = None

    @property
    def modes(self) -> tuple[IdentifiedMode, ...]:
        """Every mode separated from the noise, by frequency (empty when none)."""
        return self.result.modes


def analyze_bag(
    bag: str | Path,
    beam: BeamParameters,
    config: IdentifierConfig,
    show_progress: bool = True,
    arm_joints: int | None = None,
    band: tuple[float, float] | None = None,
) -> BagAnalysis:
    """Identifies the modes, and a drop test's stiffness, from a whole bag (B.12, B.20-B.22).

    A drop test (``/tip_load``, or a release found in the poses) is identified as one; any
    other record (a tap, a pluck, a shaker switched off, ``/tip_imu`` alone) by its free
    vibrations (:mod:`~lumpbeam_ros.core.ident.free_vibration`), the headline figures those
    of the one that rang longest.

    Args:
        bag: The bag folder, with ``/tip_pose`` and (optionally) ``/tip_load``, or
            ``/tip_imu``.
        beam: Supplies L, g and the masses.
        config: Identifier settings; the fit may run to the record's end whatever
            ``max_fit_s`` says, since the whole record is one window.
        show_progress: Draw a progress bar while reading.
        arm_joints: For an arm's bag, its number of joints: the free vibration is the one
            after the last move on ``/joint_states`` (in place of a load release).
        band: ``(low, high)`` Hz the modes are looked for in (``None``: up to the record's
            Nyquist frequency, and a drop test's configured band).

    Returns:
        The analysis; its :attr:`BagAnalysis.modes` are the modes, its ``rest`` (arm) the
        joint angles they were measured at.

    Raises:
        BagError: Not a bag or no usable ``/tip_pose`` or ``/tip_imu`` (or, for an arm,
            ``/joint_states``).
        LumpbeamError: Too few samples, no move or no rest after it, named with the bag.
    """
    topics = BagReader(bag).topics
    imu = None
    if TIP_IMU in topics:
        imu = _analyze_imu(Path(bag), topics, config, band)
        if POSE_TOPIC not in topics:
            return imu
    window = read_window(bag, show_progress)
    config = replace(config, max_fit_s=math.inf)
    if band is not None:
        config = replace(config, min_frequency_hz=band[0], max_frequency_hz=band[1])
    if arm_joints is not None:
        return replace(_analyze_ring_down(Path(bag), window, beam, config, arm_joints), imu=imu)
    whole = window
    window, split = keep_release_segment(window, config)
    arm_hint = ''
    if JOINT_STATES in topics:
        arm_hint = f'taken as a drop test, but the bag has {JOINT_STATES}: an arm? (--arm FILE)'
    notes = tuple(note for note in (window.counts.note(), split, arm_hint) if note)
    try:
        result, fit = identify_from(window, beam, config, strict=True)
    except LumpbeamError as exc:
        raise LumpbeamError(f'{bag}: {exc}') from None
    lines = steady_lines(whole.t, whole.z)
    if not result.ok and LOAD_TOPIC not in topics:
        # No drop test in it: a record of another excitation (a tap, a pluck)?
        hints = _hints(Path(bag), topics, whole.t)
        record = analyze_record(whole.t, whole.z, config, band, hints)
        if record.events:
            return BagAnalysis(
                Path(bag), whole, record.identification, None, notes, lines=record.lines,
                events=record.events, imu=imu,
            )  # fmt: skip
        lines = record.lines
    release = FreeVibration(float(result.release.time_s.value), window.end_s, 'release')
    events = (EventModes(release, result),) if result.ok else ()
    return BagAnalysis(Path(bag), window, result, fit, notes, lines=lines, events=events, imu=imu)


def _analyze_imu(
    bag: Path,
    topics: Mapping[str, Any],
    config: IdentifierConfig,
    band: tuple[float, float] | None,
) -> BagAnalysis:
    """A ``/tip_imu`` record: the acceleration along its axis of largest motion."""
    series = read_accelerations(bag)
    axes = np.vstack([series.x, series.y, series.z])
    finite = np.all(np.isfinite(axes), axis=0)
    spread = [float(np.std(a[finite])) if finite.any() else 0.0 for a in axes]
    window = clean_window(series.t, axes[int(np.argmax(spread))])
    if len(window) < 16:
        raise BagError(f'{bag}: {TIP_IMU} holds {len(window)} usable samples')
    record = analyze_record(window.t, window.z, config, band, _hints(bag, topics, window.t))
    notes = tuple(note for note in (window.counts.note(),) if note)
    return BagAnalysis(
        bag, window, record.identification, None, notes, lines=record.lines,
        events=record.events, quantity='acceleration',
    )  # fmt: skip


def _hints(bag: Path, topics: Mapping[str, Any], t: np.ndarray) -> list[tuple[float, str]]:
    """The excitations the bag names: ``/tip_load`` changes and the ends of joint moves."""
    hints: list[tuple[float, str]] = []
    if LOAD_TOPIC in topics:
        loads = read_load_events(bag, LOAD_TOPIC)
        changed = np.flatnonzero(np.diff(loads.kg) != 0.0) + 1
        hints += [(float(loads.t[k]), 'release') for k in changed]
    if JOINT_STATES in topics:
        joints = read_joint_states(bag)
        for rest in rest_stretches(joints.t, joints.angles, 1e-3):
            if rest.after_move:
                hints.append((rest.start_s, 'move_end'))
    return [(when, kind) for when, kind in hints if t[0] <= when <= t[-1]]


def record_json(analysis: BagAnalysis) -> dict[str, Any]:
    """``events`` and ``lines`` of ``lumpbeam analyze``'s JSON (and ``tip_imu``'s own)."""
    out: dict[str, Any] = {
        'events': [event.as_dict() for event in analysis.events],
        'lines': [line.as_dict() for line in analysis.lines],
    }
    if analysis.imu is not None:
        imu = analysis.imu
        out['tip_imu'] = {
            'status': imu.result.status.name,
            'message': imu.result.message,
            'modes': [mode.as_dict() for mode in imu.modes],
            **record_json(replace(imu, imu=None)),
        }
    return out


def identify_ring_down(
    window: PoseWindow,
    joints: JointSeries,
    beam: BeamParameters,
    config: IdentifierConfig,
) -> tuple[Identification, FitState | None, JointRest, PoseWindow]:
    """The modes of an arm's free vibration after its last move (the core of ``--arm``).

    Args:
        window: The tip poses (x and z).
        joints: The joint angles (``/joint_states``).
        beam: Passed through to the identification (no load leaves: its B.12 figures stay
            undetermined).
        config: Identifier settings (``ring_down.rest_tolerance_rad``, the fit's).

    Returns:
        The identification, its fit, the joints' rest after the last move and the window
        analysed (z: the tip along its swing).

    Raises:
        LumpbeamError: The joints never move, or rest for fewer than ``quality.min_samples``
            pose periods after their last move.
    """
    rest = last_ring_down(
        rest_stretches(joints.t, joints.angles, config.rest_tolerance_rad),
        min_rest_s(window, config.min_samples),
    )
    swing, release = swing_after(window, rest)
    result, fit = identify_from(swing, beam, config, strict=True, release=release)
    return result, fit, rest, swing


def _analyze_ring_down(
    bag: Path, window: PoseWindow, beam: BeamParameters, config: IdentifierConfig, joints: int
) -> BagAnalysis:
    """An arm's bag: the free vibration from where the joints last stopped to the end."""
    series = read_joint_states(bag)
    if series.angles.shape[1] != joints:
        raise LumpbeamError(
            f'{bag}: {JOINT_STATES} has {series.angles.shape[1]} joint(s) '
            f'({", ".join(series.names)}), the arm {joints}'
        )
    try:
        result, fit, rest, swing = identify_ring_down(window, series, beam, config)
    except LumpbeamError as exc:
        raise LumpbeamError(f'{bag}: {exc}') from None
    notes = tuple(note for note in (window.counts.note(),) if note)
    return BagAnalysis(bag, swing, result, fit, notes, rest)
