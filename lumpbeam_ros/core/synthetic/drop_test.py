"""The synthetic drop-test bag of ``lumpbeam synth`` (doc/interfaces.md, 'Command line').

The model is simulated under the drop-test load schedule and written as a rosbag2 MCAP bag:
``/tip_pose`` (the measurement: with pose noise and any hidden effects), ``/tip_pose_truth``
(the exact pose of the beam at each stamp), ``/tip_load`` (on change and at 1 Hz) and
``/beam_markers`` (the true beam, the measured tip, the load and the board, at 30 Hz).
"""

from __future__ import annotations

import math
import shutil
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import (
    MARKERS_RATE_HZ,
    POSE_RATE_HZ,
    TIP_LOAD,
    TIP_POSE,
    TIP_POSE_TRUTH,
)
from lumpbeam_ros.core.bagio import BagWriter
from lumpbeam_ros.core.model.parameters import (
    EFFECT_PARAMETERS,
    BeamParameters,
    DropTestConfig,
    effect_value_problem,
)
from lumpbeam_ros.core.model.simulate import DEFAULT_STEP_S, drop_test_events, simulate_loads
from lumpbeam_ros.core.model.trajectory import TipTrajectory
from lumpbeam_ros.core.synthetic.reference_sensor import (
    ReferenceSamples,
    ReferenceSensorOptions,
    simulate_reference_sensor,
    write_reference_points,
)
from lumpbeam_ros.core.vision.config import load_camera_config
from lumpbeam_ros.core.vision.placement import board_placement
from lumpbeam_ros.core.viz.marker_messages import write_scene
from lumpbeam_ros.core.viz.markers import (
    BeamScene,
    BoardPlacement,
    TipPoint,
    lifetime_for_rate,
    marker_sample_indices,
)

if TYPE_CHECKING:
    from lumpbeam_ros.core.synthetic.images import ImageOptions, ImageStream

#: Pitch noise per metre of position noise: the camera sees the board about 1 m away.
PITCH_NOISE_PER_M = 1.0

#: How often ``/tip_load`` repeats its value (doc/interfaces.md, 'Topics': at least 1 Hz).
LOAD_REPEAT_S = 1.0

#: Most samples one simulated stream may hold: the whole record is simulated in memory
#: (about 1.8 kB a sample: the angles, poses, truth and the solver's grid), so this bounds
#: it near 1 GB; 2777 s at the default 180 Hz.
MAX_SAMPLES = 500_000


@dataclass(frozen=True)
class SynthOptions:
    """What ``lumpbeam synth`` varies.

    Attributes:
        duration_s: Record length, s.
        rate_hz: Pose rate, Hz.
        noise_m: Standard deviation of the position noise on ``/tip_pose``, m; the pitch
            gets ``noise_m * PITCH_NOISE_PER_M`` rad.
        seed: Seed of the noise.
        effects: Hidden effects, doc/interfaces.md, 'Missing effects' name to parameter value.
        markers_rate_hz: Rate of ``/beam_markers``, Hz; 0 writes none.
    """

    duration_s: float = 12.0
    rate_hz: float = POSE_RATE_HZ
    noise_m: float = 20e-6
    seed: int = 0
    effects: Mapping[str, float] = field(default_factory=dict)
    markers_rate_hz: float = MARKERS_RATE_HZ


def parse_effect(text: str) -> tuple[str, float]:
    """Parses ``NAME=VALUE`` for ``--effect``.

    Args:
        text: The option's value, e.g. ``'coulomb_friction=1.0'``.

    Returns:
        The effect's contract name and its parameter.

    Raises:
        LumpbeamError: Not ``NAME=VALUE``, an unknown name, or a value outside the effect's
            limits (:data:`~lumpbeam_ros.core.model.parameters.EFFECTS`).
    """
    name, sep, value_text = text.partition('=')
    name = name.strip()
    if not sep:
        raise LumpbeamError(f'--effect {text!r}: expected NAME=VALUE')
    if name not in EFFECT_PARAMETERS:
        raise LumpbeamError(
            f'--effect {text!r}: unknown effect {name!r}; '
            f'choose from {", ".join(EFFECT_PARAMETERS)}'
        )
    try:
        value = float(value_text)
    except ValueError:
        raise LumpbeamError(f'--effect {text!r}: {value_text!r} is not a number') from None
    problem = effect_value_problem(name, value)
    if problem is not None:
        raise LumpbeamError(f'--effect {text!r}: {EFFECT_PARAMETERS[name]} {problem}')
    return name, value


#: ``--effect none``: no effect hidden at all (the demo hides one by default).
NO_EFFECT = 'none'


def parse_effects(texts: Sequence[str]) -> dict[str, float]:
    """Parses every ``--effect`` given: ``NAME=VALUE`` each, or ``none`` alone.

    Raises:
        LumpbeamError: A bad ``NAME=VALUE`` (:func:`parse_effect`), or ``none`` beside others.
    """
    if list(texts) == [NO_EFFECT]:
        return {}
    if NO_EFFECT in texts:
        raise LumpbeamError(f'--effect {NO_EFFECT} stands alone: it hides no effect')
    return dict(parse_effect(text) for text in texts)


def with_effects(beam: BeamParameters, effects: Mapping[str, float]) -> BeamParameters:
    """Returns the beam with the given effects switched on (added to any it has)."""
    combined = beam.effects
    for name, value in effects.items():
        combined = combined.with_effect(name, value)
    return replace(beam, effects=combined)


def simulate_experiment(
    beam: BeamParameters, drop: DropTestConfig, options: SynthOptions
) -> tuple[TipTrajectory, TipTrajectory]:
    """Simulates the drop test as measured and as it truly was.

    Args:
        beam: The nominal beam.
        drop: The load and its release time.
        options: Duration, rate and hidden effects.

    Returns:
        ``(measured, truth)``: the measurement without noise (every effect, the sensor's
        latency and scale included) and the true pose at the same stamps (without them).
    """
    hidden = with_effects(beam, options.effects)
    count = int(math.floor(options.duration_s * options.rate_hz + 1e-9)) + 1
    t = np.arange(count) / options.rate_hz
    events = drop_test_events(drop)
    measured = simulate_loads(hidden, t, events, drop.load_kg)
    true_sensor = replace(hidden, effects=hidden.effects.physical())
    if true_sensor == hidden:
        return measured, measured
    return measured, simulate_loads(true_sensor, t, events, drop.load_kg)


def check_sample_count(duration_s: float, rates_hz: Mapping[str, float]) -> None:
    """Refuses a record that needs more than :data:`MAX_SAMPLES` samples in one stream.

    Args:
        duration_s: Record length, s.
        rates_hz: Each stream's name and rate, Hz (the poses, the solver's grid, ...); the
            fastest is checked.

    Raises:
        LumpbeamError: Too many samples; the message names the limit.
    """
    name, rate = max(rates_hz.items(), key=lambda item: item[1])
    count = duration_s * rate
    if not count <= MAX_SAMPLES:
        raise LumpbeamError(
            f'duration {duration_s:g} s at {rate:g} Hz ({name}) is {count:.3g} samples; '
            f'the limit is {MAX_SAMPLES} ({MAX_SAMPLES / rate:.0f} s at {rate:g} Hz), '
            'each simulated in memory'
        )


def load_messages(drop: DropTestConfig, duration_s: float) -> list[tuple[float, float]]:
    """``/tip_load`` samples: the load at 0 s, at every whole second, and at the release."""
    stamps = sorted({*np.arange(0.0, duration_s + 1e-9, LOAD_REPEAT_S), drop.release_time_s})
    return [
        (float(s), drop.load_kg if s < drop.release_time_s else 0.0)
        for s in stamps
        if s <= duration_s
    ]


def _check_record(
    drop: DropTestConfig, options: SynthOptions, tracker: ReferenceSensorOptions | None
) -> None:
    """Refuses a record that ends before the release or holds too many samples."""
    if options.duration_s <= drop.release_time_s:
        raise LumpbeamError(
            f'duration {options.duration_s} s ends before the release at {drop.release_time_s} s'
        )
    rates = {'poses': options.rate_hz, 'simulation grid': 1.0 / DEFAULT_STEP_S}
    if tracker is not None:
        rates['tracker'] = tracker.rate_hz
    check_sample_count(options.duration_s, rates)


@dataclass
class _Record:
    """What a drop-test bag holds, simulated: the streams :func:`_write_record` writes.

    Attributes:
        beam: The nominal beam (its segments drawn on ``/beam_markers``).
        measured: The measured tip, before pose noise.
        truth: The true tip and joint angles.
        noise: Pose noise added to ``measured``: x, z (m) and pitch (rad) rows.
        points: The reference sensor's points (``None``: none).
        camera: The camera filming the measured motion (``None``: no images).
        drawn: Indices of the samples drawn on ``/beam_markers``.
        board: The checkerboard drawn with them.
        lifetime: Their lifetime, s.
    """

    beam: BeamParameters
    measured: TipTrajectory
    truth: TipTrajectory
    noise: np.ndarray
    points: ReferenceSamples | None
    camera: ImageStream | None
    drawn: set[int] = field(default_factory=set)
    board: BoardPlacement | None = None
    lifetime: float = 0.0


def _write_record(bag: BagWriter, record: _Record, loads: list[tuple[float, float]]) -> None:
    """Writes every stream of a simulated record, in log-time order."""
    measured, truth, noise, points = record.measured, record.truth, record.noise, record.points
    assert truth.q is not None  # the truth keeps its joint angles
    written = 0
    pending_loads = iter(loads)
    pending = next(pending_loads, None)
    for i, stamp in enumerate(measured.t):
        # In log-time order: the reference points since the last pose come before a load
        # change at this stamp (a flush between the two would put them after).
        if points is not None:
            written = write_reference_points(bag, points, written, stamp)
        while pending is not None and pending[0] <= stamp:
            bag.write_float(TIP_LOAD, pending[0], pending[1])
            pending = next(pending_loads, None)
        x, z = measured.x[i] + noise[0, i], measured.z[i] + noise[1, i]
        bag.write_pose(TIP_POSE, stamp, x, z, measured.pitch[i] + noise[2, i])
        bag.write_pose(TIP_POSE_TRUTH, stamp, truth.x[i], truth.z[i], truth.pitch[i])
        if i in record.drawn:
            scene = BeamScene(
                record.beam.segment_length_m,
                phi=truth.q[i],
                measured=TipPoint(x, z),
                load_kg=float(truth.load_kg[i]),
                board=record.board,
            )
            write_scene(bag, stamp, scene, record.lifetime)
        if record.camera is not None:
            record.camera.write_next(bag)
    if points is not None:
        write_reference_points(bag, points, written, math.inf)


def write_drop_test_bag(
    out: str | Path,
    beam: BeamParameters,
    drop: DropTestConfig,
    options: SynthOptions,
    *,
    tracker: ReferenceSensorOptions | None = None,
    images: ImageOptions | None = None,
) -> tuple[TipTrajectory, TipTrajectory]:
    """Simulates the drop test and writes it as a bag.

    Args:
        out: The bag folder to create (it must not exist).
        beam: The nominal beam.
        drop: The load and its release time.
        options: What to vary.
        tracker: Also write ``/tracker/point`` from a simulated laser tracker
            (:mod:`~lumpbeam_ros.core.synthetic.reference_sensor`).
        images: When given, also ``/camera/image_raw`` and ``/camera/camera_info``: the
            camera films the measured motion (hidden effects included, no pose noise), one
            frame per pose stamp (see :mod:`lumpbeam_ros.core.synthetic.images`).

    Returns:
        ``(measured, truth)`` as :func:`simulate_experiment` returns them.

    Raises:
        BagError: ``out`` exists or cannot be written.
        LumpbeamError: The record ends before the release, or needs more than
            :data:`MAX_SAMPLES` samples in a stream.
    """
    _check_record(drop, options, tracker)
    measured, truth = simulate_experiment(beam, drop, options)
    rng = np.random.default_rng(options.seed)
    noise = options.noise_m * rng.standard_normal((3, len(measured)))
    noise[2] *= PITCH_NOISE_PER_M
    points = None
    if tracker is not None:
        hidden = with_effects(beam, options.effects)
        points = simulate_reference_sensor(hidden, drop, options.duration_s, tracker)
    camera = None
    if images is not None:
        # OpenCV only when filming: the pose-only bag needs none (`pip install lumpbeam_ros`).
        from lumpbeam_ros.core.synthetic.images import ImageStream

        camera = ImageStream(measured, images)
    record = _Record(beam, measured, truth, noise, points, camera)
    if options.markers_rate_hz > 0.0:
        record.drawn = set(marker_sample_indices(truth.t, options.markers_rate_hz).tolist())
        config = load_camera_config(None if images is None else images.camera_config)
        record.board = board_placement(config)
        record.lifetime = lifetime_for_rate(options.markers_rate_hz)
    created = not Path(out).exists()  # BagWriter refuses an existing OUT: never removed below
    try:
        with BagWriter(out) as bag:
            _write_record(bag, record, load_messages(drop, options.duration_s))
    except BaseException:
        # Interrupted (Ctrl-C, SIGTERM) or failed: a bag cut short is not the record asked for.
        if created:
            shutil.rmtree(out, ignore_errors=True)
        raise
    return measured, truth
