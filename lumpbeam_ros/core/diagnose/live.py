"""The live discrepancy workflow: which stretch of the stream to diagnose, what it says.

:class:`LiveBuffer` keeps the measured tip (``/tip_pose``), the simulator's prediction
(``/tip_pose_predicted``) and the load changes (``/tip_load``) as they arrive, and says when a
stretch is complete: a *ring-down* (from ``pre_release_s`` before a load change until the
decay has lasted ``decay_s``, or earlier once its amplitude fell below ``min_amplitude_m``),
or a fixed *window* of the latest ``window_s``. The stretch becomes the same
:class:`~lumpbeam_ros.core.diagnose.measurement.Record` that ``lumpbeam diagnose`` builds from a
bag (:func:`~lumpbeam_ros.core.diagnose.measurement.record_from_series`), and :func:`diagnose_live`
runs the same workflow on it (:func:`~lumpbeam_ros.core.diagnose.workflow.diagnose`), reduced to
the small, picklable :class:`LiveDiagnosis` a worker process sends back. :func:`status_values`
turns that into the status level, message and key-value pairs of ``doc/interfaces.md``
("/model_discrepancy").
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import TIP_POSE
from lumpbeam_ros.base.schema import Bounds, setting
from lumpbeam_ros.core.bagio.tipbuffer import TipBuffer
from lumpbeam_ros.core.bagio.tipseries import SampleCounts
from lumpbeam_ros.core.diagnose.measurement import (
    MIN_SAMPLES_AFTER_EVENT,
    Record,
    record_from_series,
)
from lumpbeam_ros.core.diagnose.workflow import diagnose
from lumpbeam_ros.core.ident.settings import IdentifierConfig
from lumpbeam_ros.core.model.parameters import EFFECT_PARAMETERS, BeamParameters

Trigger = Literal['ring_down', 'window']
TRIGGERS: tuple[Trigger, ...] = ('ring_down', 'window')

#: DiagnosticStatus levels (as numbers: the core does not import ROS messages).
OK, WARN, ERROR, STALE = 0, 1, 2, 3

_POSITIVE = Bounds(0.0, low_open=True)
#: The amplitude of a ring-down is measured over this last stretch of it, s.
AMPLITUDE_SPAN_S = 0.5
#: A load reading is dated through the latest this many poses (a backlog of them).
DATING_POSES = 400


@dataclass(frozen=True)
class LiveDiagnosisConfig:
    """When the live diagnosis runs (the diagnosis node's parameters).

    Attributes:
        trigger: ``'ring_down'`` after each load change, or ``'window'`` every ``window_s``.
        pre_release_s: Rest kept before the load change, s.
        decay_s: A ring-down is complete once it has lasted this long, s.
        min_amplitude_m: ... or earlier, once the peak-to-peak tip z over the last
            ``AMPLITUDE_SPAN_S`` falls below twice this (0: never).
        window_s: Length of a fixed window, s.
        keep_s: The buffers hold this much of the latest data, s.
        reset_jump_back_s: A pose stamped this far before the newest one, and confirmed by
            the pose after it, is the clock going back (a looping bag): the stream starts
            over (:class:`~lumpbeam_ros.core.bagio.tipbuffer.TipBuffer`).
        max_rate_hz: Highest pose rate the buffers are sized for; faster input shortens
            what they hold.
    """

    trigger: Trigger = setting(
        'trigger',
        'ring_down',
        'ring_down: diagnose each load change once its decay is complete; window: '
        'diagnose every window_s of data (it must hold a load change)',
        choices=TRIGGERS,
    )
    pre_release_s: float = setting(
        'ring_down.pre_release_s',
        1.0,
        'rest before the load change that a ring-down includes',
        's',
        Bounds(0.0, low_open=True),
    )
    decay_s: float = setting(
        'ring_down.decay_s',
        8.0,
        'a ring-down is complete once the decay has lasted this long (at least 2 s of '
        'poses at 180 Hz are needed after the change)',
        's',
        Bounds(2.0, 600.0),
    )
    min_amplitude_m: float = setting(
        'ring_down.min_amplitude_m',
        0.0,
        'a ring-down is complete earlier once the tip z swings less than this (half '
        'peak-to-peak over the last 0.5 s); 0: only decay_s ends it',
        'm',
        Bounds(0.0, 1.0),
    )
    window_s: float = setting(
        'window_s', 10.0, 'length of a window (trigger window)', 's', Bounds(2.0, 600.0)
    )
    keep_s: float = setting(
        'keep_s',
        60.0,
        'the node keeps this much of the latest data (longer than any ring-down)',
        's',
        Bounds(5.0, 3600.0),
    )
    reset_jump_back_s: float = setting(
        'stream.reset_jump_back_s',
        1.0,
        'a pose stamped this far before the newest one (and the pose after it) is the clock '
        'going back, a looping bag: the node starts over on the new time line',
        's',
        _POSITIVE,
    )
    # Not a parameter: the buffers are sized as the identifier's window is.
    max_rate_hz: float = IdentifierConfig.max_rate_hz


@dataclass(frozen=True)
class Stretch:
    """A complete stretch of the stream to diagnose.

    Attributes:
        start_s: First stamp, s.
        end_s: Last stamp, s.
        release_s: The load change it follows (NaN for a window without one).
        release_uncertainty_s: How early the load change may be dated, s (the poses'
            spacing around it when it was dated through them, else 0).
        release_lead_s: How much later than ``release_s`` the send times put it, s: the
            reading's send time interpolated between those of the poses sent around it
            (within ``[0, release_uncertainty_s]``; exact for a player on time).
    """

    start_s: float
    end_s: float
    release_s: float
    release_uncertainty_s: float = 0.0
    release_lead_s: float = 0.0


@dataclass(frozen=True)
class LiveDiagnosis:
    """What one live diagnosis found (the workflow's result, reduced to what is published).

    Attributes:
        missing_effect: An effect name, ``'none'`` or ``'unexplained'``.
        missing_effects: ``(name, parameters)`` of every effect named, in the order chosen.
        gap_before_rms_m: RMS gap of the nominal model (k_tE and beta refit), m.
        gap_after_rms_m: RMS gap of the augmented model, m.
        reason: The workflow's reason for its verdict.
        stretch: What was diagnosed.
        seconds: Wall time of the diagnosis, s.
        samples: The stretch's poses kept and dropped.
    """

    missing_effect: str
    missing_effects: tuple[tuple[str, dict[str, float]], ...]
    gap_before_rms_m: float
    gap_after_rms_m: float
    reason: str
    stretch: Stretch
    seconds: float = 0.0
    samples: SampleCounts = field(default_factory=SampleCounts)

    @property
    def effect_parameters(self) -> dict[str, float]:
        """Every named effect's parameters, by contract name (``latency_s``...)."""
        return {k: v for _, params in self.missing_effects for k, v in params.items()}

    def simulator_parameters(self) -> dict[str, float]:
        """The simulator node's parameters that carry the named effects (finite ones only).

        Returns:
            ``{'effects.<name>.<parameter>': value}``.
        """
        out = {}
        for name, params in self.missing_effects:
            param = EFFECT_PARAMETERS.get(name)
            if param is not None and param in params and math.isfinite(params[param]):
                out[f'effects.{name}.{param}'] = float(params[param])
        return out


def _entry(item: Any) -> tuple[str, dict[str, float]]:
    if isinstance(item, Mapping):
        return str(item['name']), dict(item.get('parameters') or {})
    return str(item.name), dict(getattr(item, 'parameters', {}) or {})


def named_effects(result: Any) -> tuple[tuple[str, dict[str, float]], ...]:
    """The effects a workflow result names, whichever form it has.

    A result with ``missing_effects`` (entries with a ``name`` and ``parameters``) gives
    those; one without gives its single ``missing_effect`` with ``effect_parameters``.

    Args:
        result: A :class:`~lumpbeam_ros.core.diagnose.workflow.Diagnosis`.

    Returns:
        ``(name, parameters)`` per named effect; empty for ``none`` and ``unexplained``.
    """
    listed = getattr(result, 'missing_effects', None)
    if listed is not None:
        return tuple(_entry(item) for item in listed)
    if result.missing_effect in ('none', 'unexplained'):
        return ()
    return ((result.missing_effect, dict(result.effect_parameters)),)


def diagnose_live(record: Record, beam: BeamParameters, stretch: Stretch) -> LiveDiagnosis:
    """Runs the offline workflow on one stretch (in a worker: it takes seconds).

    A sensor latency no longer than the release's dating uncertainty is not named: the
    verdict is ``none``, saying why (the gaps are the workflow's). A longer one is named less
    the release's lead (:attr:`Stretch.release_lead_s`): the workflow sees the release where
    it was dated, up to a pose's spacing early, and that much of the delay is the dating's.

    Args:
        record: The stretch as a record.
        beam: The nominal beam.
        stretch: Where the record came from.

    Returns:
        The reduced result.

    Raises:
        LumpbeamError: The workflow cannot measure the record's decay.
    """
    import time

    start = time.perf_counter()
    result = diagnose(record, beam)
    named, reason = named_effects(result), result.decision.reason
    missing = result.missing_effect
    latency = dict(named).get('sensor_latency', {}).get('latency_s', math.nan)
    # The margin: the delay is fitted to a few microseconds, the dating's bound is exact.
    if len(named) == 1 and 0.0 <= latency <= 1.1 * stretch.release_uncertainty_s:
        # Dated up to that much late, the release alone can show such a delay.
        missing, named = 'none', ()
        reason = (
            f'the delay found, {latency * 1e3:.2f} ms, is within how late the release may be '
            f'dated ({stretch.release_uncertainty_s * 1e3:.2f} ms: /tip_load has no stamp)'
        )
    elif len(named) == 1 and stretch.release_lead_s > 0.0 and math.isfinite(latency):
        ((name, parameters),) = named
        named = ((name, {**parameters, 'latency_s': latency - stretch.release_lead_s}),)
    return LiveDiagnosis(
        missing_effect=missing,
        missing_effects=named,
        gap_before_rms_m=float(result.gap_before.rms_m),
        gap_after_rms_m=float(result.gap_after.rms_m),
        reason=reason,
        stretch=stretch,
        seconds=time.perf_counter() - start,
        samples=record.counts,
    )


def status_values(result: LiveDiagnosis) -> tuple[int, str, list[tuple[str, str]]]:
    """The ``lumpbeam/diagnosis`` status of a diagnosis (``doc/interfaces.md``).

    OK when the nominal model explains the data, WARN when effects are named, ERROR for
    ``unexplained``; never OK for a stretch with many of its poses dropped
    (:attr:`~lumpbeam_ros.core.bagio.tipseries.SampleCounts.untrusted`): WARN, saying so.
    Numbers are written as Python ``repr`` of floats, as on ``/beam_params``.

    Args:
        result: The diagnosis.

    Returns:
        ``(level, message, [(key, value), ...])``.
    """
    names = [name for name, _ in result.missing_effects]
    if result.missing_effect == 'unexplained':
        level, message = ERROR, f'unexplained gap: {result.reason}'
    elif names:
        shown = ', '.join(f'{k} = {v:.4g}' for k, v in result.effect_parameters.items())
        level, message = WARN, f'missing {", ".join(names)} ({shown})'
    else:
        level, message = OK, 'the model explains the data'
    if result.samples.untrusted:
        level = max(level, WARN)
        message = f'{message}; /tip_pose: {result.samples.note()} in the stretch'
    pairs = [
        ('missing_effect', result.missing_effect),
        ('missing_effects', ','.join(names) or result.missing_effect),
        *((k, repr(float(v))) for k, v in result.effect_parameters.items()),
        ('gap_before_rms_m', repr(result.gap_before_rms_m)),
        ('gap_after_rms_m', repr(result.gap_after_rms_m)),
        ('window_start_s', repr(result.stretch.start_s)),
        ('window_end_s', repr(result.stretch.end_s)),
        ('release_time_s', repr(result.stretch.release_s)),
        ('reason', result.reason),
    ]
    return level, message, pairs


class LiveBuffer:
    """The latest measured and predicted tip poses and load changes, and complete stretches.

    Args:
        settings: When a stretch is complete.
    """

    def __init__(self, settings: LiveDiagnosisConfig):
        self.settings = settings
        self.measured = self._buffer()
        self.predicted = self._buffer()
        self.loads: list[tuple[float, float]] = []  # (time, kg) in arrival order
        self.predicted_count = 0
        self.measured_count = 0
        self._done_until = -math.inf  # stretches ending here or before were handed out
        # The recent measured poses' stamps, and when they were sent minus their stamps, s.
        self._sent_after_stamp: deque[tuple[float, float]] = deque(maxlen=DATING_POSES)
        # A load change's time: its dating's uncertainty and lead (Stretch), s.
        self._dating_s: dict[float, tuple[float, float]] = {}
        # (sent, kg) of the loads to date; bounded for a stream of loads without poses.
        self._undated: deque[tuple[float, float]] = deque(maxlen=DATING_POSES)

    def _buffer(self) -> TipBuffer:
        """A buffer of ``keep_s``; a stamp that far back is the clock going back."""
        s = self.settings
        return TipBuffer(s.keep_s, s.max_rate_hz, s.reset_jump_back_s)

    @property
    def latest_s(self) -> float:
        """The newest measured stamp (NaN before the first)."""
        return self.measured.newest_s if len(self.measured) else math.nan

    def push_measured(self, t: float, z: float, pitch: float, sent_s: float = math.nan) -> bool:
        """Adds a measured pose, or counts why not (:class:`~.tipbuffer.TipBuffer`).

        A clock that jumped back (a looping bag) starts the stream over: the prediction, the
        stretches and the load changes belong to the old time line; the mass hanging (the
        last reading received) is kept as the load from the new line's start.

        Args:
            t: Header stamp, s.
            z: Tip z, m.
            pitch: Tip pitch, rad.
            sent_s: When the pose was sent (its DDS source timestamp, or the node's clock at
                its arrival), s; NaN: unknown. It dates the load readings on the poses' time
                line (:meth:`push_load`).

        Returns:
            Whether the pose was stored.
        """
        resets = self.measured.counts.resets
        stored = self.measured.push(t, z, pitch)
        if self.measured.counts.resets != resets:
            # The new time line starts with the mass in force: the last reading received
            # (one sent before its first pose is still undated), as the identifier keeps it.
            latest = [kg for _, kg in (*self.loads, *self._undated)][-1:]
            self.loads[:] = [(-math.inf, kg) for kg in latest]
            self._undated.clear()
            self._sent_after_stamp.clear()
            self.predicted = self._buffer()
            self._done_until = -math.inf
        if stored and math.isfinite(sent_s):
            self._sent_after_stamp.append((t, sent_s - t))
            self._date_loads_sent_before(sent_s)
        self.measured_count += stored
        return stored

    def push_predicted(self, t: float, z: float, pitch: float) -> bool:
        """Adds a predicted pose of the simulator (the same rule as the measured ones)."""
        stored = self.predicted.push(t, z, pitch)
        self.predicted_count += stored
        return stored

    def push_load(self, sent_s: float, kg: float) -> None:
        """Adds a ``/tip_load`` reading (``Float64`` has no stamp), dated by when it was sent.

        It is dated on the poses' time line: by ``sent_s`` itself when the poses' stamps are
        on the same clock (a live camera); else (a bag played, on ``/clock`` or wall time, at
        any rate) at the stamp of the last pose sent before it, once the first pose sent
        after it has arrived, the spacing of the two its uncertainty
        (:attr:`Stretch.release_uncertainty_s`) and its send time interpolated between
        theirs its lead (:attr:`Stretch.release_lead_s`). A reading before any pose is the
        load hanging from the start.

        Args:
            sent_s: When the reading was sent (as ``sent_s`` of :meth:`push_measured`), s.
            kg: Mass at the tip, kg.
        """
        if not self.measured_count:
            self._add_load(-math.inf, kg)
        elif (
            self._sent_after_stamp
            and abs(self._sent_after_stamp[-1][1]) > self.settings.reset_jump_back_s
        ):
            # Dated once the first pose sent after it has arrived (the two topics may be
            # delivered out of step, a backlog of poses behind the load).
            self._undated.append((sent_s, kg))
        else:
            self._add_load(sent_s, kg)

    def _date_loads_sent_before(self, sent_s: float) -> None:
        """Dates the load readings sent before the pose sent at ``sent_s``.

        A player sends in the bag's order however late it runs: a reading falls between the
        stamps of the poses sent just before and just after it. It is dated at the first (a
        release dated late would show as a negative delay, which no sensor has), the gap to
        the second its uncertainty, and where its send time falls between theirs its lead.
        """
        while self._undated and self._undated[0][0] < sent_s:
            sent_load, kg = self._undated.popleft()
            sent = [(t, t + ahead) for t, ahead in self._sent_after_stamp]
            before = [pair for pair in sent if pair[1] <= sent_load]
            after, sent_after = next(pair for pair in sent if pair[1] > sent_load)
            dated, sent_before = before[-1] if before else (sent[0][0], sent_load)
            share = (sent_load - sent_before) / (sent_after - sent_before)
            self._add_load(dated, kg, after - dated, min(max(share, 0.0), 1.0) * (after - dated))

    def _add_load(self, t: float, kg: float, uncertainty: float = 0.0, lead: float = 0.0) -> None:
        if self.loads and (t < self.loads[-1][0] or t == -math.inf):
            self.loads.clear()
        if not self.loads or kg != self.loads[-1][1]:
            self.loads.append((t, kg))
            self._dating_s[t] = (uncertainty, lead)
        # The reading in force keep_s before the newest pose is the oldest one needed.
        while len(self.loads) > 1 and self.loads[1][0] <= self.latest_s - self.settings.keep_s:
            del self.loads[0]
        self._dating_s = {when: self._dating_s.get(when, (0.0, 0.0)) for when, _ in self.loads}

    def clear(self) -> None:
        """Forgets everything (the clock went back); the counts are kept."""
        self.measured.clear()
        self.predicted = self._buffer()
        self.loads.clear()
        self._done_until = -math.inf
        self._sent_after_stamp.clear()
        self._undated.clear()

    def missing_input(self) -> str | None:
        """What the diagnosis lacks to start, in words (``None``: nothing)."""
        if self.measured_count == 0 and self.predicted_count > 0:
            return '/tip_pose: no measured pose received (only /tip_pose_predicted arrives)'
        if self.measured_count == 0:
            return '/tip_pose: no measured pose received yet'
        if not self.loads:
            return '/tip_load: no load reading received yet'
        return None

    def _releases(self) -> list[float]:
        return [t for t, _ in self.loads[1:]]

    def next_stretch(self) -> Stretch | None:
        """The next complete stretch not handed out yet (then it never is again).

        Returns:
            The stretch, or ``None`` while none is complete.
        """
        latest = self.latest_s
        if math.isnan(latest) or not self.loads:
            return None
        s = self.settings
        if s.trigger == 'window':
            oldest = self.measured.latest()[0].start_s
            start = oldest if self._done_until == -math.inf else self._done_until
            if latest - start < s.window_s:
                return None
            end = start + s.window_s
            self._done_until = end
            inside = [t for t in self._releases() if start < t < end]
            return Stretch(start, end, inside[0] if inside else math.nan)
        for release in self._releases():
            if release <= self._done_until:
                continue
            ring_down_end = self._ring_down_end(release, latest)
            if ring_down_end is None:
                return None
            self._done_until = ring_down_end
            uncertainty, lead = self._dating_s.get(release, (0.0, 0.0))
            return Stretch(release - s.pre_release_s, ring_down_end, release, uncertainty, lead)
        return None

    def _ring_down_end(self, release: float, latest: float) -> float | None:
        s = self.settings
        if latest >= release + s.decay_s:
            return release + s.decay_s
        recent = self.measured.between(latest - AMPLITUDE_SPAN_S, latest)[0]
        t, z = recent.t, recent.z
        after = self.measured.between(release, latest)[0].t > release
        enough = np.count_nonzero(after) >= MIN_SAMPLES_AFTER_EVENT  # what a record needs
        if s.min_amplitude_m > 0.0 and enough and t.size > 2:
            if float(np.ptp(z)) < 2.0 * s.min_amplitude_m:
                return latest
        return None

    def record(self, stretch: Stretch) -> Record:
        """The measured poses of a stretch as a diagnosis record.

        A load change is dated when its ``/tip_load`` reading arrived (``Float64`` has no
        stamp), not from the poses: a release timed from the measured onset would absorb a
        ``sensor_latency``, the very delay the diagnosis looks for. A reading delivered late
        therefore shortens the latency found by as much.

        Args:
            stretch: A stretch of :meth:`next_stretch`.

        Returns:
            The record (the load before the stretch as its initial load).

        Raises:
            LumpbeamError: No load change inside the stretch, too few poses after it.
        """
        poses, counts = self.measured.between(stretch.start_s, stretch.end_s)
        initial = self.loads[0][1]
        events = []
        for time, kg in self.loads[1:]:
            if time <= stretch.start_s:
                initial = kg
            elif time < stretch.end_s:
                events.append((time, kg))
        if not events:
            raise LumpbeamError(
                f'no load change between {stretch.start_s:.3f} and {stretch.end_s:.3f} s: '
                'a diagnosis needs a release to compare against'
            )
        return record_from_series(poses, initial, events, TIP_POSE, dropped=counts)

    def prediction_gap(self, start_s: float, end_s: float) -> float:
        """RMS of measured minus predicted tip z over a stretch (the running model's gap).

        Args:
            start_s: From, s.
            end_s: To, s.

        Returns:
            The RMS in m, NaN when the prediction does not cover the measured stamps.
        """
        measured = self.measured.between(start_s, end_s)[0]
        predicted = self.predicted.between(start_s - 1.0, end_s + 1.0)[0]
        t, z, tp, zp = measured.t, measured.z, predicted.t, predicted.z
        covered = (t >= tp[0]) & (t <= tp[-1]) if tp.size > 1 else np.zeros(t.size, bool)
        if np.count_nonzero(covered) < 0.9 * max(t.size, 1) or t.size == 0:
            return math.nan
        residual = z[covered] - np.interp(t[covered], tp, zp)
        return float(np.sqrt(np.mean(residual**2)))
