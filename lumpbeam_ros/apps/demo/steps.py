"""``lumpbeam demo``: the whole pipeline on the built-in synthetic drop test, as a list of steps.

1. ``synthesize``: a drop-test bag (``/tip_pose`` with noise, ``/tip_pose_truth``,
   ``/tip_load``; images once the synthetic camera writes them).
2. ``replay``: the live graph as separate processes on a private ROS domain, the nodes as
   ``launch/drop_test.launch.yaml`` starts them (``use_sim_time:=true``): the player
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

Each step is a function of the :class:`~lumpbeam_ros.apps.demo.run.DemoRun` it fills in;
:func:`default_steps` lists them, so a step can be added or swapped without touching the
others. The run's state is :mod:`~lumpbeam_ros.apps.demo.run`, the accounting (step 3)
:mod:`~lumpbeam_ros.apps.demo.accounting`, the results (step 7)
:mod:`~lumpbeam_ros.apps.demo.summary`; this module orchestrates the processes.
"""

from __future__ import annotations

import shutil
from collections.abc import Callable, Sequence

from lumpbeam_ros.apps.demo.accounting import count
from lumpbeam_ros.apps.demo.graph import (
    ProcessGraph,
    launched_command,
    python_command,
    wait_for_graph,
    wait_for_quiet,
)
from lumpbeam_ros.apps.demo.live_diagnosis import (
    wait_for_verdict,
)
from lumpbeam_ros.apps.demo.recording import (
    analyze_recording,
    normalize_recording,
)
from lumpbeam_ros.apps.demo.run import (
    BAGS_DIR,
    CAMERA_INFO_TOPIC,
    CAMERA_MODULE,
    CAMERA_REPLAY_RATE,
    CLI_MODULE,
    DIAGNOSIS_NODE_MODULE,
    IDENTIFIER_MODULE,
    IMAGE_TOPIC,
    LIVE_DECAY_S,
    PLAYER_DELAY_S,
    RECORDED_TOPICS,
    SIMULATOR_MODULE,
    TRAILING_TOPICS,
    VERDICT_WAIT_S,
    DemoOptions,
    DemoRun,
    Step,
    fresh_bags_dir,
    module_available,
    run_steps,
)
from lumpbeam_ros.apps.demo.summary import figures, summarize
from lumpbeam_ros.apps.json_output import plain_json, write_json
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import (
    BEAM_PARAMS,
    CAMERA_NODE,
    CLOCK,
    DIAGNOSIS_NODE,
    IDENTIFIER_NODE,
    RECORDER_NODE,
    SIMULATOR_NODE,
    TIP_LOAD,
    TIP_POSE,
    TIP_POSE_PREDICTED,
)
from lumpbeam_ros.base.resources import packaged
from lumpbeam_ros.core.bagio import BagReader, read_tip_poses
from lumpbeam_ros.core.model.parameters import load_beam_config
from lumpbeam_ros.nodes.counts import COUNTS_DIR_ENV
from lumpbeam_ros.nodes.launch_file import NodeLaunch, read_launch_file

#: The graph the demo replays the experiment through (share folder, or the repository).
LAUNCH_FILE = 'launch/drop_test.launch.yaml'


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
    nodes = launched_nodes()
    simulator_args = ['-p', f'adopt_identified:={str(run.options.adopt_identified).lower()}']
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
        graph.start('simulator', launched_command(nodes[SIMULATOR_NODE], *simulator_args))
        run.nodes = [SIMULATOR_MODULE]
        if module_available(IDENTIFIER_MODULE):
            graph.start('identifier', launched_command(nodes[IDENTIFIER_NODE]))
            run.nodes.append(IDENTIFIER_MODULE)
            readers[TIP_POSE] += 1
            readers[TIP_LOAD] += 1
        if module_available(DIAGNOSIS_NODE_MODULE):
            _start_diagnosis_node(graph, run, readers, nodes[DIAGNOSIS_NODE])
        if run.with_camera:
            graph.start('camera', launched_command(nodes[CAMERA_NODE]))
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


def launched_nodes() -> dict[str, NodeLaunch]:
    """The nodes of the drop-test chain's launch file on sim time, by executable.

    The demo runs the graph a user starts with ``lumpbeam launch`` (or ``ros2 launch``),
    each node with the few settings of the demo's own added.
    """
    plan = read_launch_file(packaged(LAUNCH_FILE), {'use_sim_time': 'true'})
    return {node.executable: node for node in plan.nodes}


def _start_diagnosis_node(
    graph: ProcessGraph, run: DemoRun, readers: dict[str, int], node: NodeLaunch
) -> None:
    """Starts the diagnosis node on the ring-down, adopting into the simulator."""
    args = ['-p', 'adopt:=true']
    args += ['-p', f'ring_down.decay_s:={LIVE_DECAY_S}']
    if run.options.beam_config is not None:
        args += ['-p', f'beam_config:={run.options.beam_config}']
    graph.start('diagnosis', launched_command(node, *args))
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
