"""A ``lumpbeam demo`` run: its options, folders and state, and the graph's fixed parts.

The state is what the steps fill in; the fixed parts are the node modules, the topics
recorded and who publishes them.
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

from lumpbeam_ros.apps.demo.recording import (
    RecordingAnalysis,
)
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import (
    BEAM_MARKERS,
    BEAM_PARAMS,
    CAMERA_INFO,
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
    SIMULATOR_NODE,
    TIP_LOAD,
    TIP_POSE,
    TIP_POSE_PREDICTED,
)
from lumpbeam_ros.core.model.parameters import BeamParameters, DropTestConfig

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


def analysis_of(run: DemoRun) -> RecordingAnalysis:
    """The run's offline analysis.

    Raises:
        LumpbeamError: The analyze step has not run.
    """
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
