"""``lumpbeam demo``: the whole pipeline on the built-in synthetic drop test, as a list of steps.

1. ``synthesize``: a drop-test bag (``/tip_pose`` with noise, ``/tip_pose_truth``,
   ``/tip_load``; images once the synthetic camera writes them).
2. ``replay``: the live graph as separate processes on a private ROS domain: the player
   (``lumpbeam play``, with ``/clock``), the simulator node (``use_sim_time``), the identifier
   node and the camera node when they are installed (the camera only for a bag with images;
   it then makes ``/tip_pose`` from the images instead of the player), and the recorder
   (``lumpbeam record``), stopped with SIGINT once the replay is over and the nodes have
   worked through their queues.
3. ``count``: per topic, the messages published (the player's and the nodes' own counters)
   against those recorded, and the camera frames offered against those tracked.
4. ``normalize``: the recording with every message logged at its sim time.
5. ``analyze``: offline identification of the recorded ``/tip_pose`` and ``/tip_load``, and
   the prediction residual.
6. ``diagnose``: the model-discrepancy workflow on the recording, in this process (as
   ``lumpbeam diagnose`` runs it: the same JSON and figures).
7. ``figures`` and ``summary``: measured against predicted (Figs. B.8-B.10), the table.

Each step is a function of the :class:`DemoRun` it fills in; :func:`default_steps` lists them,
so a step can be added or swapped without touching the others.
"""

from __future__ import annotations

import importlib.util
import math
import shutil
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

from lumpbeam_ros.apps.demo.graph import (
    ProcessGraph,
    node_command,
    python_command,
    wait_for_graph,
    wait_for_quiet,
)
from lumpbeam_ros.apps.demo.live_diagnosis import (
    live_diagnosis,
    live_diagnosis_lines,
    wait_for_verdict,
)
from lumpbeam_ros.apps.demo.recording import (
    RecordingAnalysis,
    analyze_recording,
    live_value,
    normalize_recording,
    prediction_lag,
)
from lumpbeam_ros.apps.json_output import plain_json, write_json
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import (
    BEAM_MARKERS,
    BEAM_PARAMS,
    CAMERA_INFO,
    CAMERA_NODE,
    CLOCK,
    CLOCK_TYPE,
    DIAGNOSIS_NODE,
    DIAGNOSTIC_ARRAY,
    FLOAT64,
    IDENTIFIER_NODE,
    IMAGE,
    MARKER_ARRAY,
    MODEL_DISCREPANCY,
    POSE_STAMPED,
    RECORDER_NODE,
    SIMULATOR_NODE,
    TIP_LOAD,
    TIP_POSE,
    TIP_POSE_PREDICTED,
)
from lumpbeam_ros.core.bagio import BagReader, read_tip_poses
from lumpbeam_ros.core.model.adopt import first_mode
from lumpbeam_ros.core.model.parameters import BeamParameters, DropTestConfig, load_beam_config
from lumpbeam_ros.core.viz.markers import MARKERS_TOPIC
from lumpbeam_ros.nodes.counts import COUNTS_DIR_ENV, read_counts

SIMULATOR_MODULE = 'lumpbeam_ros.nodes.simulator_node'
IDENTIFIER_MODULE = 'lumpbeam_ros.nodes.identifier_node'
CAMERA_MODULE = 'lumpbeam_ros.nodes.camera_node'
DIAGNOSIS_NODE_MODULE = 'lumpbeam_ros.nodes.diagnosis_node'
#: The live diagnosis takes the ring-down up to this long after the release: short enough
#: that the diagnosis (about 1 s of CPU per second of record) and the adoption land inside
#: the replay, long enough for the workflow (2 s of poses after the release).
LIVE_DECAY_S = 2.3
#: Longest wait after the replay for the live diagnosis (tens of seconds on a busy machine).
VERDICT_WAIT_S = 120.0
CLI_MODULE = 'lumpbeam_ros.apps.cli.main'
IMAGE_TOPIC = IMAGE
CAMERA_INFO_TOPIC = CAMERA_INFO
#: What the recorder records, with the types the probe announces them with.
RECORDED_TOPICS = {
    TIP_POSE: POSE_STAMPED,
    TIP_LOAD: FLOAT64,
    TIP_POSE_PREDICTED: POSE_STAMPED,
    BEAM_PARAMS: DIAGNOSTIC_ARRAY,
    CLOCK: CLOCK_TYPE,
    BEAM_MARKERS: MARKER_ARRAY,
    MODEL_DISCREPANCY: DIAGNOSTIC_ARRAY,
}
#: Who publishes each recorded topic, by the name of its counts file
#: (:mod:`lumpbeam_ros.nodes.counts`); ``/tip_pose`` comes from the camera node when it runs.
PUBLISHERS = {
    TIP_POSE: 'player',
    TIP_LOAD: 'player',
    TIP_POSE_PREDICTED: SIMULATOR_NODE,
    BEAM_MARKERS: SIMULATOR_NODE,
    BEAM_PARAMS: IDENTIFIER_NODE,
    MODEL_DISCREPANCY: DIAGNOSIS_NODE,
    CLOCK: 'player',
}
#: The topics the nodes are still producing when the player is done.
TRAILING_TOPICS = {
    TIP_POSE: POSE_STAMPED,
    TIP_POSE_PREDICTED: POSE_STAMPED,
}
#: Camera frames are replayed at this fraction of real time: the graph runs on the player's
#: /clock, so only the wall time changes, and on 2 cores the camera node, the identifier,
#: the simulator and the diagnosis node's worker then keep up with best-effort frames.
CAMERA_REPLAY_RATE = 0.5
#: The player waits this long before its first message: its publishers must be discovered
#: by the recorder's subscriptions first (a new process takes 1-3 s on a busy machine).
PLAYER_DELAY_S = 4.0
#: The folder under ``out`` that holds the demo's bags; its marker file lets a new run
#: replace it without ever deleting a folder the demo did not make.
BAGS_DIR = 'bags'
MARKER = '.lumpbeam-demo'

#: What the built-in experiment hides for the diagnosis to find: a camera whose stamps are
#: 15 ms late. It leaves the beam's frequency, damping and stiffness as they are, so the
#: identification is still compared with the nominal truth, while the nominal model's
#: prediction visibly runs ahead of the measurement.
HIDDEN_EFFECT = {'sensor_latency': 0.015}

#: The paper's figures for its beam (section B.3.2): f_E = 3.24 Hz, k_tE = 3899.1 N m/rad and
#: c_tE = 0.08, whose damping ratio by B.22 is c_tE / (2 omega_d).
PAPER = {
    'natural_frequency_hz': 3.24,
    'damping_ratio': 0.08 / (2.0 * 2.0 * math.pi * 3.24),
    'stiffness_total_nm_per_rad': 3899.1,
}


@dataclass(frozen=True)
class DemoOptions:
    """What ``lumpbeam demo`` varies.

    Attributes:
        out: Output folder (bags, logs, figures, summary).
        duration_s: Length of the synthetic record, s (the load drops at 2 s).
        seed: Seed of the pose noise.
        adopt_identified: Let the simulator adopt the identifier's live estimates.
        domain_id: ROS domain of the graph; when ``None``, one no other lumpbeam process holds.
        beam_config: Beam parameter file (the package's paper_beam.yaml when ``None``).
        ready_timeout_s: Longest wait for the nodes to join the graph, s.
        image_size: Width and height of the synthetic camera's frames; ``None`` plays the
            bag's ``/tip_pose`` instead of running the camera node.
        effects: Effects of doc/interfaces.md hidden in the synthetic data, for the diagnosis
            step to find (default: the camera's stamps 15 ms late).
    """

    out: Path = Path('results')
    duration_s: float = 12.0
    seed: int = 0
    adopt_identified: bool = False
    domain_id: int | None = None
    beam_config: Path | None = None
    ready_timeout_s: float = 60.0
    image_size: tuple[int, int] | None = (640, 480)
    effects: Mapping[str, float] = field(default_factory=lambda: dict(HIDDEN_EFFECT))


class DemoFolders:
    """The folders of a demo run under its ``options.out`` (a base of the runs' state)."""

    options: Any

    @property
    def out(self) -> Path:
        """The output folder."""
        return Path(self.options.out)

    @property
    def log_dir(self) -> Path:
        """Where the child processes' logs go."""
        return self.out / 'logs'


@dataclass
class DemoRun(DemoFolders):
    """The state the steps share and fill in.

    Attributes:
        options: The options.
        beam: The beam of the synthetic experiment.
        drop: Its load and release time.
        echo: Where progress lines go.
        input_bag: The synthetic bag.
        recorded_bag: What the recorder wrote.
        normalized_bag: The recording in sim time.
        with_camera: Whether the camera node made ``/tip_pose`` from images.
        nodes: The node modules that ran in the graph.
        topic_counts: Per recorded topic: its publisher, messages published and recorded.
        image_counts: Camera frames offered by the player, received and tracked by the camera
            node (empty without the camera).
        analysis: The offline analysis.
        diagnosis: The diagnosis as ``lumpbeam diagnose`` writes it (JSON), when it ran.
        figures: Written figures.
        summary: The machine-readable summary (also ``summary.json``).
        step_seconds: Wall time of each step, s.
    """

    options: DemoOptions
    beam: BeamParameters
    drop: DropTestConfig
    echo: Callable[[str], None] = print
    input_bag: Path = Path()
    recorded_bag: Path = Path()
    normalized_bag: Path = Path()
    with_camera: bool = False
    nodes: list[str] = field(default_factory=list)
    topic_counts: dict[str, dict[str, Any]] = field(default_factory=dict)
    image_counts: dict[str, int | None] = field(default_factory=dict)
    analysis: RecordingAnalysis | None = None
    diagnosis: dict[str, Any] | None = None
    camera_rms_m: float | None = None
    figures: list[Path] = field(default_factory=list)
    summary: dict[str, Any] = field(default_factory=dict)
    step_seconds: dict[str, float] = field(default_factory=dict)

    @property
    def counts_dir(self) -> Path:
        """Where the nodes leave their message counts."""
        return self.log_dir / 'counts'


Step = tuple[str, Callable[[DemoRun], None]]


RunT = TypeVar('RunT', bound=DemoFolders)


def module_available(name: str) -> bool:
    """Whether a module of this package is installed (without importing it)."""
    try:
        return importlib.util.find_spec(name) is not None
    except ModuleNotFoundError:
        return False


def synthesize(run: DemoRun) -> None:
    """Writes the synthetic drop-test bag (``out/bags/input``)."""
    from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, write_drop_test_bag
    from lumpbeam_ros.core.synthetic.images import ImageOptions

    bags = fresh_bags_dir(run.out / BAGS_DIR)
    run.input_bag = bags / 'input'
    run.recorded_bag = bags / 'recorded'
    run.normalized_bag = bags / 'recorded_sim_time'
    options = SynthOptions(
        duration_s=run.options.duration_s, seed=run.options.seed, effects=run.options.effects
    )
    size = run.options.image_size
    images = None if size is None else ImageOptions(size[0], size[1], seed=run.options.seed)
    write_drop_test_bag(run.input_bag, run.beam, run.drop, options, images=images)
    hidden = ', '.join(f'{k}={v:g}' for k, v in run.options.effects.items()) or 'none'
    frames = 'no images' if size is None else f'{size[0]}x{size[1]} camera frames'
    run.echo(
        f'  wrote {run.input_bag} ({run.options.duration_s:g} s, release at '
        f'{run.drop.release_time_s:g} s, {frames}, hidden effect: {hidden})'
    )


def replay(run: DemoRun) -> None:
    """Runs the live graph on the synthetic bag and records it (``out/bags/recorded``)."""
    topics = BagReader(run.input_bag).topics
    run.with_camera = IMAGE_TOPIC in topics and module_available(CAMERA_MODULE)
    sim_time = ('-p', 'use_sim_time:=true')
    simulator_args = [
        *sim_time,
        '-p',
        f'adopt_identified:={str(run.options.adopt_identified).lower()}',
    ]
    if run.options.beam_config is not None:
        simulator_args += ['-p', f'beam_config:={run.options.beam_config}']
    # Readers each recorded topic must have before the replay: the probe's and the
    # recorder's, plus the simulator's own inputs.
    readers = dict.fromkeys(RECORDED_TOPICS, 2)
    readers[TIP_LOAD] += 1
    readers[CLOCK] += 1
    readers[BEAM_PARAMS] += 1
    shutil.rmtree(run.counts_dir, ignore_errors=True)
    with ProcessGraph(run.log_dir, run.options.domain_id) as graph:
        graph.env[COUNTS_DIR_ENV] = str(run.counts_dir)
        run.echo(f'  ROS_DOMAIN_ID={graph.domain_id}, logs in {run.log_dir}')
        graph.start('simulator', node_command(SIMULATOR_MODULE, *simulator_args))
        run.nodes = [SIMULATOR_MODULE]
        if module_available(IDENTIFIER_MODULE):
            graph.start('identifier', node_command(IDENTIFIER_MODULE, *sim_time))
            run.nodes.append(IDENTIFIER_MODULE)
            readers[TIP_POSE] += 1
            readers[TIP_LOAD] += 1
        if module_available(DIAGNOSIS_NODE_MODULE):
            _start_diagnosis_node(graph, run, readers)
        if run.with_camera:
            graph.start('camera', node_command(CAMERA_MODULE, *sim_time))
            run.nodes.append(CAMERA_MODULE)
            readers[IMAGE_TOPIC] = 1
        graph.start(
            'recorder',
            python_command(CLI_MODULE, 'record', str(run.recorded_bag), *RECORDED_TOPICS),
        )
        wait_for_graph(
            graph,
            [SIMULATOR_NODE, RECORDER_NODE]
            + ([DIAGNOSIS_NODE] if DIAGNOSIS_NODE_MODULE in run.nodes else []),
            readers,
            run.options.ready_timeout_s,
            announce=RECORDED_TOPICS,
        )
        played = [IMAGE_TOPIC, TIP_LOAD] if run.with_camera else [TIP_POSE, TIP_LOAD]
        if run.with_camera and CAMERA_INFO_TOPIC in topics:
            played.append(CAMERA_INFO_TOPIC)
        graph.start(
            'player',
            python_command(
                CLI_MODULE,
                'play',
                str(run.input_bag),
                '--topics',
                *played,
                '--delay',
                str(PLAYER_DELAY_S),
                '--rate',
                str(CAMERA_REPLAY_RATE if run.with_camera else 1.0),
            ),
        )
        others = [name for name in graph.children if name != 'player']
        graph.wait('player', run.options.duration_s * 4 + 30.0, watch=others)
        # Only a record that holds the whole ring-down gets a verdict to wait for.
        ends = run.drop.release_time_s + LIVE_DECAY_S < run.options.duration_s
        live = DIAGNOSIS_NODE_MODULE in run.nodes and ends
        if live and not wait_for_verdict(graph, VERDICT_WAIT_S, others):
            run.echo(f'  warning: no live diagnosis within {VERDICT_WAIT_S:g} s of the replay')
        # The camera node may be a few frames behind: let the nodes finish their queues, then
        # stop them before the recorder, which takes in what they sent last.
        trailing = dict(TRAILING_TOPICS)
        if not run.with_camera:
            del trailing[TIP_POSE]  # the player's, and it is done
        wait_for_quiet(graph, trailing, timeout_s=run.options.ready_timeout_s)
        for name in others:
            if name != 'recorder':
                try:
                    graph.interrupt(name)
                except LumpbeamError as exc:
                    # The recording is complete; a node's untidy exit only deserves a note.
                    run.echo(f'  warning: {exc}')
        graph.interrupt('recorder')  # must stop cleanly: it closes the bag
    run.echo(f'  recorded {run.recorded_bag} with {", ".join(run.nodes)}')


def count(run: DemoRun) -> None:
    """Sets what was published against what was recorded, per topic, and prints it."""
    counts = read_counts(run.counts_dir)
    recorded = {name: entry.count for name, entry in BagReader(run.recorded_bag).topics.items()}
    publishers = dict(PUBLISHERS)
    if run.with_camera:
        publishers[TIP_POSE] = CAMERA_NODE
    run.topic_counts = {}
    for topic in RECORDED_TOPICS:
        publisher = publishers[topic]
        published = counts.get(publisher, {}).get('published', {}).get(topic)
        run.topic_counts[topic] = {
            'publisher': publisher,
            'published': published,
            'recorded': recorded.get(topic, 0),
        }
    if run.with_camera:
        camera = counts.get(CAMERA_NODE, {})
        run.image_counts = {
            'offered': counts.get('player', {}).get('published', {}).get(IMAGE_TOPIC),
            'received': camera.get('received', {}).get(IMAGE_TOPIC),
            'tracked': camera.get('published', {}).get(TIP_POSE),
        }
    for line in count_lines(run.topic_counts, run.image_counts):
        run.echo(line)


def count_lines(
    topic_counts: Mapping[str, Mapping[str, Any]], image_counts: Mapping[str, int | None]
) -> list[str]:
    """The table of :func:`count`: published, recorded and lost per topic."""
    lines = [f'  {"topic":<22}{"publisher":<16}{"published":>10}{"recorded":>10}{"lost":>6}']
    for topic, row in topic_counts.items():
        published = row['published']
        lost = '-' if published is None else str(published - row['recorded'])
        shown = '-' if published is None else str(published)
        lines.append(
            f'  {topic:<22}{row["publisher"]:<16}{shown:>10}{row["recorded"]:>10}{lost:>6}'
        )
    if image_counts:
        shown = {k: '-' if v is None else str(v) for k, v in image_counts.items()}
        lines.append(
            f'  {IMAGE_TOPIC}: {shown["offered"]} frames offered by the player, '
            f'{shown["received"]} received by the camera node (best effort), '
            f'{shown["tracked"]} tracked'
        )
    return lines


def _start_diagnosis_node(graph: ProcessGraph, run: DemoRun, readers: dict[str, int]) -> None:
    """Starts the diagnosis node on the ring-down, adopting into the simulator."""
    args = ['-p', 'use_sim_time:=true', '-p', 'adopt:=true']
    args += ['-p', f'ring_down.decay_s:={LIVE_DECAY_S}']
    if run.options.beam_config is not None:
        args += ['-p', f'beam_config:={run.options.beam_config}']
    graph.start('diagnosis', node_command(DIAGNOSIS_NODE_MODULE, *args))
    run.nodes.append(DIAGNOSIS_NODE_MODULE)
    for topic in (TIP_POSE, TIP_LOAD, TIP_POSE_PREDICTED):
        readers[topic] += 1


def normalize(run: DemoRun) -> None:
    """Writes the recording with every message logged at its sim time."""
    normalize_recording(run.recorded_bag, run.normalized_bag)


def analyze(run: DemoRun) -> None:
    """Identifies the recorded drop test and compares the prediction with the measurement."""
    run.analysis = analyze_recording(run.normalized_bag, run.beam)
    if not run.with_camera:
        played = len(read_tip_poses(run.input_bag).t)
        recorded = len(run.analysis.measured.t)
        if recorded < played:
            run.echo(f'  warning: the recorder got {recorded} of {played} poses (slow discovery?)')


def diagnose(run: DemoRun) -> None:
    """Diagnoses the recording as ``lumpbeam diagnose`` does; its JSON and figures are kept."""
    from lumpbeam_ros.apps.plots.diagnosis import plot_diagnosis
    from lumpbeam_ros.core.diagnose.measurement import read_record
    from lumpbeam_ros.core.diagnose.workflow import diagnose as diagnose_record

    record = read_record(run.normalized_bag)
    for note in record.notes:
        run.echo(f'  warning: {note}')
    result = diagnose_record(record, run.beam)
    run.diagnosis = plain_json(result.as_dict())
    write_json(run.out / 'diagnosis.json', run.diagnosis)
    plot_diagnosis(result, run.out / 'figures')


def figures(run: DemoRun) -> None:
    """Draws measured against predicted (whole record, and the release) with the residual."""
    from lumpbeam_ros.apps.plots.demo import plot_measured_vs_predicted

    analysis = _analysis(run)
    release = run.drop.release_time_s
    folder = run.out / 'figures'
    run.figures = [
        plot_measured_vs_predicted(
            analysis.residual,
            folder / 'tip_measured_vs_predicted.png',
            release_time_s=release,
        ),
        plot_measured_vs_predicted(
            analysis.residual,
            folder / 'tip_release_zoom.png',
            span=(release - 0.5, release + 3.0),
            release_time_s=release,
            title='Tip after the release: measured and predicted',
        ),
    ]
    if run.with_camera:
        run.figures.append(_camera_figure(run, folder / 'tip_tracked_vs_truth.png'))
    if MARKERS_TOPIC in BagReader(run.normalized_bag).topics:
        run.figures.append(_beam_figure(run, folder / 'beam_markers.png'))


def _beam_figure(run: DemoRun, path: Path) -> Path:
    """Draws the recorded ``/beam_markers`` around the release (what a viewer shows)."""
    from lumpbeam_ros.apps.plots.beam import drop_snapshot_times, plot_beam_snapshots

    f_n, _, _ = first_mode(run.beam, 0.0)
    release = run.drop.release_time_s
    return plot_beam_snapshots(
        run.normalized_bag,
        path,
        times=drop_snapshot_times(release, 1.0 / f_n),
        release_time_s=release,
        title="The beam in the demo's recording, as /beam_markers draw it",
    )


def _camera_figure(run: DemoRun, path: Path) -> Path:
    """Draws the camera node's poses against the motion its frames showed (noise-free)."""
    from lumpbeam_ros.apps.plots.demo import plot_measured_vs_predicted, prediction_residual
    from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, simulate_experiment

    options = SynthOptions(duration_s=run.options.duration_s, effects=run.options.effects)
    seen, _ = simulate_experiment(run.beam, run.drop, options)
    tracked = _analysis(run).measured
    residual = prediction_residual(tracked.t, tracked.z, seen.t, seen.z)
    run.camera_rms_m = residual.rms()
    return plot_measured_vs_predicted(
        residual,
        path,
        release_time_s=run.drop.release_time_s,
        title='Tip: tracked by the camera node and as the camera saw it',
        labels=('camera node /tip_pose', 'synthetic truth (what the frames show)'),
    )


def summarize(run: DemoRun) -> None:
    """Builds the summary (identified, live, truth, paper), prints it, writes summary.json."""
    analysis = _analysis(run)
    ident = analysis.identification
    f_n, _, zeta = first_mode(run.beam, 0.0)
    truth = {
        'natural_frequency_hz': f_n,
        'damping_ratio': zeta,
        'stiffness_total_nm_per_rad': run.beam.k_total_nm_per_rad,
    }
    rows = {}
    for key in truth:
        rows[key] = {
            'identified': ident.figure(key).value,
            'identified_std': ident.figure(key).std,
            'live': live_value(analysis, key),
            'truth': truth[key],
            'paper': PAPER[key],
        }
    residual = analysis.residual
    after = run.drop.release_time_s
    lag, aligned_rms = prediction_lag(analysis.measured, analysis.predicted, after)
    run.summary = {
        'status': ident.status.name,
        'release_time_s': ident.release.time_s.value,
        'quantities': rows,
        'prediction_rms_m': residual.rms(),
        'prediction_rms_after_release_m': residual.rms(start=after),
        'prediction_max_m': float(abs(residual.residual).max()),
        'prediction_lag_s': lag,
        'prediction_rms_aligned_m': aligned_rms,
        'measured_samples': int(analysis.measured.t.size),
        'predicted_samples': int(analysis.predicted.t.size),
        'nodes': list(run.nodes),
        'topic_counts': run.topic_counts,
        'image_counts': run.image_counts,
        'with_camera': run.with_camera,
        'camera_rms_m': run.camera_rms_m,
        'figures': [str(p) for p in run.figures],
        'step_seconds': dict(run.step_seconds),
    }
    if run.diagnosis is not None:
        run.summary['diagnosis'] = run.diagnosis
    live = live_diagnosis(run.recorded_bag, residual, run.drop.release_time_s)
    if live is not None:
        run.summary['live_diagnosis'] = live
    for line in summary_lines(run.summary):
        run.echo(line)
    write_json(run.out / 'summary.json', run.summary)


def summary_lines(summary: dict[str, Any]) -> list[str]:
    """The human summary table of :func:`summarize` (also of its JSON read back)."""
    labels = {
        'natural_frequency_hz': ('natural frequency', 'Hz', '{:.4f}'),
        'damping_ratio': ('damping ratio', '', '{:.5f}'),
        'stiffness_total_nm_per_rad': ('k_tE (B.12)', 'N m/rad', '{:.1f}'),
    }
    lines = [
        f'{"quantity":<24}{"identified (offline)":>26}{"live node":>12}{"truth":>12}{"paper":>10}',
    ]
    for key, (label, unit, fmt) in labels.items():
        row = summary['quantities'][key]
        ident = f'{fmt.format(row["identified"])} +- {row["identified_std"]:.2g}'
        live = row['live']  # NaN in a run, None when read back from summary.json
        live = fmt.format(live) if live is not None and math.isfinite(live) else '-'
        name = f'{label} ({unit})' if unit else label
        lines.append(
            f'{name:<24}{ident:>26}{live:>12}{fmt.format(row["truth"]):>12}'
            f'{fmt.format(row["paper"]):>10}'
        )
    lines.append(
        f'prediction vs measurement: RMS {summary["prediction_rms_m"] * 1e3:.3f} mm '
        f'({summary["prediction_rms_after_release_m"] * 1e3:.3f} mm after the release), '
        f'max {summary["prediction_max_m"] * 1e3:.3f} mm over {summary["measured_samples"]} '
        f'samples'
    )
    if summary.get('prediction_lag_s') is not None and math.isfinite(summary['prediction_lag_s']):
        lines.append(
            f'  of which timing: the prediction runs {summary["prediction_lag_s"] * 1e3:.1f} ms '
            f'late (the /tip_load delivery delay, and any latency the camera hides); '
            f'shifted by it, RMS '
            f'{summary["prediction_rms_aligned_m"] * 1e3:.3f} mm after the release'
        )
    if summary.get('camera_rms_m') is not None:
        lines.append(
            f'camera node vs the synthetic truth: RMS {summary["camera_rms_m"] * 1e6:.1f} um '
            f'in tip z'
        )
    if 'diagnosis' in summary:
        lines += diagnosis_lines(summary['diagnosis'])
    if 'live_diagnosis' in summary:
        lines += live_diagnosis_lines(summary['live_diagnosis'])
    return lines


def diagnosis_lines(diagnosis: dict[str, Any]) -> list[str]:
    """The diagnosis in two lines: the effect found and the gap before and after adding it."""
    found = diagnosis.get('missing_effect')
    parameters = ', '.join(
        f'{k} = {v:.4g}' for k, v in (diagnosis.get('effect_parameters') or {}).items()
    )
    lines = [f'diagnosis: missing effect {found}' + (f' ({parameters})' if parameters else '')]
    before, after = diagnosis.get('gap_before'), diagnosis.get('gap_after')
    if before and after:
        lines.append(
            f'  gap to the measurement: RMS {before["rms_m"] * 1e3:.3f} mm with the nominal '
            f'model, {after["rms_m"] * 1e3:.3f} mm with the effect added'
        )
    return lines


def default_steps() -> list[Step]:
    """The demo's steps, in order."""
    return [
        ('synthesize', synthesize),
        ('replay', replay),
        ('count', count),
        ('normalize', normalize),
        ('analyze', analyze),
        ('diagnose', diagnose),
        ('figures', figures),
        ('summary', summarize),
    ]


def run_demo(
    options: DemoOptions,
    steps: Sequence[Step] | None = None,
    echo: Callable[[str], None] = print,
) -> DemoRun:
    """Runs the demo's steps in order.

    Args:
        options: Output folder, duration, seed...
        steps: The steps (default: :func:`default_steps`).
        echo: Where progress and the summary go.

    Returns:
        The filled-in run.

    Raises:
        LumpbeamError: A step failed (its child processes are stopped first).
        ConfigError: The beam file is malformed.
    """
    beam, drop = load_beam_config(options.beam_config)
    if options.duration_s <= drop.release_time_s + 1.0:
        raise LumpbeamError(
            f'--duration {options.duration_s:g} s leaves less than 1 s after the release at '
            f'{drop.release_time_s:g} s'
        )
    run = DemoRun(options=options, beam=beam, drop=drop, echo=echo)
    run_steps(run, list(default_steps() if steps is None else steps), run.step_seconds, echo)
    return run


def run_steps(
    run: RunT,
    steps: Sequence[tuple[str, Callable[[RunT], None]]],
    step_seconds: dict[str, float],
    echo: Callable[[str], None],
) -> None:
    """Runs steps on a run in order, numbering them and timing each into ``step_seconds``.

    Raises:
        LumpbeamError: What a step raised.
    """
    started = time.monotonic()
    for index, (name, step) in enumerate(steps, start=1):
        echo(f'[{index}/{len(steps)}] {name}')
        t0 = time.monotonic()
        step(run)
        step_seconds[name] = round(time.monotonic() - t0, 2)
    step_seconds['total'] = round(time.monotonic() - started, 2)
    echo(f'demo finished in {step_seconds["total"]:.1f} s; results in {run.out}')


def _analysis(run: DemoRun) -> RecordingAnalysis:
    if run.analysis is None:
        raise LumpbeamError('the analyze step must run before this one')
    return run.analysis


def fresh_bags_dir(path: Path) -> Path:
    """Empties (or makes) the demo's bags folder, refusing one the demo did not make.

    Raises:
        LumpbeamError: ``path`` exists without the demo's marker.
    """
    if path.exists():
        if not (path / MARKER).exists():
            raise LumpbeamError(f'{path} exists and was not made by lumpbeam demo; move it away')
        shutil.rmtree(path)
    path.mkdir(parents=True)
    (path / MARKER).write_text('bags of the last `lumpbeam demo`; replaced by the next\n')
    return path
