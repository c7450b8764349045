"""Offline analysis of a bag recorded from the live graph (ROS-free).

A recorder logs ``/tip_load`` (Float64, no header) at the wall time it arrived, while the
poses carry the replayed bag's own time (``/clock``). Recording ``/clock`` as well gives the
map between the two: :func:`normalize_recording` writes a copy in which every message is
logged at its sim time (each load reading at the ``/clock`` the graph showed when it arrived,
as a node with ``use_sim_time`` saw it), which every offline tool then reads as it reads a
synthetic bag.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lumpbeam_ros.apps.plots.demo import Residual, prediction_residual
from lumpbeam_ros.base.errors import BagError
from lumpbeam_ros.base.interface import (
    BEAM_PARAMS,
    CLOCK,
    CLOCK_TYPE,
    DIAGNOSTIC_ARRAY,
    FLOAT64,
    IDENTIFIER_STATUS,
    MODEL_DISCREPANCY,
    POSE_STAMPED,
    TIP_LOAD,
    TIP_POSE,
    TIP_POSE_PREDICTED,
    TIP_POSE_TRUTH,
)
from lumpbeam_ros.core.bagio import BagReader, BagWriter, convert, read_diagnostics, read_tip_poses
from lumpbeam_ros.core.bagio.series import read_load_events
from lumpbeam_ros.core.bagio.tipseries import TipSeries
from lumpbeam_ros.core.ident.identification import Identification
from lumpbeam_ros.core.ident.identify import identify
from lumpbeam_ros.core.ident.samples import clean_loads, clean_window
from lumpbeam_ros.core.ident.segments import keep_release_segment
from lumpbeam_ros.core.ident.settings import IdentifierConfig
from lumpbeam_ros.core.model.parameters import BeamParameters
from lumpbeam_ros.core.viz.marker_messages import MARKER_ARRAY_TYPE
from lumpbeam_ros.core.viz.markers import MARKERS_TOPIC

#: Pose topics a normalized recording keeps.
POSE_TOPICS = (TIP_POSE, TIP_POSE_PREDICTED, TIP_POSE_TRUTH)


@dataclass(frozen=True)
class RecordingAnalysis:
    """What a recorded drop test shows.

    Attributes:
        measured: ``/tip_pose``.
        predicted: ``/tip_pose_predicted``.
        load_t: ``/tip_load`` readings in sim time, s.
        load_kg: Their values, kg.
        identification: The offline identification of ``/tip_pose`` and ``/tip_load``.
        live: The last ``/beam_params`` values of the identifier node (empty if none).
        live_level: Its DiagnosticStatus level (-1 if none).
        residual: Measured against predicted, on the measured stamps.
    """

    measured: TipSeries
    predicted: TipSeries
    load_t: np.ndarray
    load_kg: np.ndarray
    identification: Identification
    live: dict[str, str]
    live_level: int
    residual: Residual


def clock_time(
    log_s: np.ndarray, clock_log_s: np.ndarray, clock_value_s: np.ndarray
) -> np.ndarray:
    """Maps log times to the sim time the graph showed then (the latest ``/clock`` before).

    Args:
        log_s: Log times to map, s.
        clock_log_s: Log times of the ``/clock`` messages, s, increasing.
        clock_value_s: Their values, s.

    Returns:
        Sim times; NaN for log times before the first ``/clock``.
    """
    index = np.searchsorted(clock_log_s, np.asarray(log_s, float), side='right') - 1
    out = np.full(index.shape, np.nan)
    valid = index >= 0
    out[valid] = np.asarray(clock_value_s, float)[index[valid]]
    return out


def read_clock(bag: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """Reads ``/clock`` as ``(log time s, clock value s)``, in log order.

    Raises:
        BagError: No ``/clock`` in the bag, or corrupt messages.
    """
    rows = [
        (convert.ns_to_seconds(ns), convert.ns_to_seconds(convert.time_ns(msg.clock)))
        for ns, msg in BagReader(bag).messages(CLOCK, CLOCK_TYPE)
    ]
    if not rows:
        raise BagError(f'{bag}: /clock has no message, so /tip_load cannot be put in sim time')
    log_s, value_s = np.array(rows).T
    return log_s, value_s


#: Status topics a normalized recording keeps, each message at its header stamp.
DIAGNOSTIC_TOPICS = (BEAM_PARAMS, MODEL_DISCREPANCY)


def normalize_recording(recorded: str | Path, out: str | Path) -> Path:
    """Copies a recording with every message logged at its sim time.

    Poses, ``/beam_params``, ``/model_discrepancy`` and ``/beam_markers`` are logged at their
    header stamps;
    ``/tip_load`` readings at the ``/clock`` shown when they were recorded (readings before
    the first ``/clock`` are dropped: they have no sim time).

    Args:
        recorded: The bag the recorder wrote (with ``/clock``).
        out: The bag folder to create.

    Returns:
        ``out``.

    Raises:
        BagError: ``/clock`` or ``/tip_load`` is missing, or ``out`` exists.
    """
    reader = BagReader(recorded)
    clock_log, clock_value = read_clock(recorded)
    loads = read_load_events(recorded)
    load_t = clock_time(loads.t, clock_log, clock_value)
    # (sim time ns, topic, message), merged into log-time order before writing: each topic
    # comes in its own order, and a bag's messages are in log-time order.
    rows: list[tuple[int, str, object]] = []
    types = {topic: POSE_STAMPED for topic in POSE_TOPICS}
    types.update({topic: DIAGNOSTIC_ARRAY for topic in DIAGNOSTIC_TOPICS})
    for topic, msgtype in types.items():
        if topic in reader.topics:
            rows += [
                (convert.time_ns(msg.header.stamp), topic, msg)
                for _, msg in reader.messages(topic, msgtype)
            ]
    rows += [
        (convert.seconds_to_ns(float(t)), TIP_LOAD, convert.float64(float(kg)))
        for t, kg in zip(load_t, loads.kg, strict=True)
        if np.isfinite(t)
    ]
    if MARKERS_TOPIC in reader.topics:
        # The simulator node stamps every marker of an array alike.
        rows += [
            (convert.time_ns(msg.markers[0].header.stamp), MARKERS_TOPIC, msg)
            for _, msg in reader.messages(MARKERS_TOPIC, MARKER_ARRAY_TYPE)
            if msg.markers
        ]
    with BagWriter(out) as bag:
        for topic in POSE_TOPICS:
            if topic in reader.topics:
                bag.add_topic(topic, types[topic])
        bag.add_topic(TIP_LOAD, FLOAT64)
        for ns, topic, msg in sorted(rows, key=lambda row: row[0]):
            bag.write_message(topic, msg, ns)
    return Path(out)


def last_live_status(bag: str | Path) -> tuple[dict[str, str], int]:
    """The latest live estimate of every key on ``/beam_params`` and the last status level.

    A key that the last windows could not estimate keeps the latest value it had: the
    stiffness (B.12) needs the release inside the window, and a 10 s window loses it near the
    end of a 12 s record while the frequency and damping stay current.

    Returns:
        The values (``repr`` strings, as published) and the last level; ``({}, -1)`` if none.
    """
    if BEAM_PARAMS not in BagReader(bag).topics:
        return {}, -1
    latest: dict[str, str] = {}
    level = -1
    for _, statuses in read_diagnostics(bag):
        for status in statuses:
            if status.name != IDENTIFIER_STATUS:
                continue
            level = status.level
            for key, value in status.values.items():
                if _is_finite_number(value) or key not in latest:
                    latest[key] = value
    return latest, level


def _is_finite_number(text: str) -> bool:
    try:
        return math.isfinite(float(text))
    except ValueError:
        return False


def analyze_recording(
    bag: str | Path, beam: BeamParameters, config: IdentifierConfig | None = None
) -> RecordingAnalysis:
    """Identifies the drop test in a normalized recording and compares it with the prediction.

    Args:
        bag: A bag from :func:`normalize_recording` (or any bag whose ``/tip_load`` is logged
            in the poses' time) with ``/tip_pose``, ``/tip_pose_predicted`` and ``/tip_load``.
        beam: The beam the identification assumes (L, g, masses; B.12).
        config: Identifier settings (defaults when ``None``).

    Returns:
        The analysis.

    Raises:
        BagError: A topic is missing or empty.
        LumpbeamError: The poses do not hold a usable drop test.
    """
    measured = read_tip_poses(bag, TIP_POSE)
    predicted = read_tip_poses(bag, TIP_POSE_PREDICTED)
    for name, series in ((TIP_POSE, measured), (TIP_POSE_PREDICTED, predicted)):
        if series.t.size == 0:
            raise BagError(f'{bag}: {name} has no message')
    loads = read_load_events(bag)
    readings = clean_loads(loads.t, loads.kg)
    window = clean_window(measured.t, measured.z, measured.pitch, readings)
    window, _ = keep_release_segment(window, config or IdentifierConfig())
    identification = identify(window, beam, config, strict=True)
    live, level = last_live_status(bag)
    residual = prediction_residual(measured.t, measured.z, predicted.t, predicted.z)
    return RecordingAnalysis(
        measured=measured,
        predicted=predicted,
        load_t=readings.t,
        load_kg=readings.kg,
        identification=identification,
        live=live,
        live_level=level,
        residual=residual,
    )


def live_value(analysis: RecordingAnalysis, key: str) -> float:
    """A float from the live ``/beam_params`` (NaN when absent or not a number)."""
    try:
        return float(analysis.live[key])
    except (KeyError, ValueError):
        return math.nan


def prediction_lag(
    measured: TipSeries,
    predicted: TipSeries,
    start_s: float,
    end_s: float = math.inf,
    max_lag_s: float = 0.2,
) -> tuple[float, float]:
    """How late the prediction runs behind the measurement, and the gap once shifted by it.

    In a live graph the simulator applies a ``/tip_load`` change when the message arrives
    (``std_msgs/Float64`` carries no stamp), so its whole ring-down is shifted by the
    message's delivery delay; this separates that timing error from the error in shape.

    Args:
        measured: ``/tip_pose``.
        predicted: ``/tip_pose_predicted``.
        start_s: Compare from this time on (the release), s.
        end_s: Compare up to (not including) this time, s.
        max_lag_s: The largest lag searched either way, s.

    Returns:
        The lag (positive: the prediction is late), s, and the RMS of measured minus the
        prediction shifted back by it over the stretch, m (NaN, NaN when they do not overlap
        there).
    """
    keep = (measured.t >= start_s) & (measured.t < end_s)
    t, z = measured.t[keep], measured.z[keep]

    def rms(lag: float) -> float:
        inside = (t + lag >= predicted.t[0]) & (t + lag <= predicted.t[-1])
        if inside.sum() < 10:
            return math.inf
        shifted = np.interp(t[inside] + lag, predicted.t, predicted.z)
        return float(np.sqrt(np.mean((z[inside] - shifted) ** 2)))

    if t.size < 10 or predicted.t.size < 10:
        return math.nan, math.nan
    step = float(np.median(np.diff(predicted.t)))
    lags = np.arange(-max_lag_s, max_lag_s + step / 2, step / 4)
    costs = np.array([rms(float(lag)) for lag in lags])
    best = int(np.argmin(costs))
    if not math.isfinite(costs[best]):
        return math.nan, math.nan
    if 0 < best < lags.size - 1:
        # A parabola through the best grid point and its neighbours.
        a, b, c = costs[best - 1 : best + 2]
        denominator = a - 2 * b + c
        offset = 0.5 * (a - c) / denominator if denominator > 0 else 0.0
        lag = float(lags[best] + offset * (lags[1] - lags[0]))
        return lag, rms(lag)
    return float(lags[best]), float(costs[best])
