"""Vibration removed across the workspace: moves shaped by a learned arm, judged by MuJoCo.

The whole path of ``lumpbeam shape --arm --tune`` on arms it has to learn first:

1. the truth is an arm file; the nominal file the lab starts from has every link's stiffness
   and damping 20 % off (up or down, drawn per link);
2. the truth rings down after three moves (the link campaign's moves of
   :mod:`lumpbeam_lab.arm_links`, each ending with a quick step of the outer joint) recorded
   as synthetic bags with 20 um of noise; their modes, identified from the bags as
   ``lumpbeam analyze`` does, fit the links from the nominal file (``--fit-links``): the
   learned arm;
3. moves across the workspace, slow and fast, small and large (the elbow through 2.6 rad in
   0.6 s), are shaped by the learned arm: ZVD for its first two modes at each move's end, and
   that shaper tuned on the learned model's simulation of the move;
4. each move, unshaped, shaped and tuned, is run on the truth in MuJoCo (its own bodies,
   hinges and integrator, :mod:`lumpbeam_lab.mujoco_arm`): the residual vibration is the
   RMS of the tip's distance from MuJoCo's rest over the 3 s after the move ends.

``python -m lumpbeam_lab.workspace_shaping [--arms two_link three_link] [--seed S]`` prints
the table: per move the residuals in MuJoCo (unshaped, untuned, tuned), the reductions, the
learned model's own prediction of the tuned residual and the time the shaping added.
"""

from __future__ import annotations

import argparse
import statistics
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from lumpbeam_lab.arm_links import ArmCase, campaign_move, nominal_arm
from lumpbeam_lab.mujoco_arm import mujoco_residual
from lumpbeam_lab.shaping_loop import minimum_jerk
from lumpbeam_ros.core.ident.arm.bag_modes import bag_observations
from lumpbeam_ros.core.ident.arm.link_fit import LinkParameterFit
from lumpbeam_ros.core.ident.settings import IdentifierConfig
from lumpbeam_ros.core.model.arm.config import ArmConfig, arm_from_mapping, load_arm_config
from lumpbeam_ros.core.model.arm.residual import WINDOW_S
from lumpbeam_ros.core.shaping.apply import shape_trajectory
from lumpbeam_ros.core.shaping.workspace import WorkspaceShaper
from lumpbeam_ros.core.synthetic.arm_bag import ArmSynthOptions, write_arm_bag

ROOT = Path(__file__).resolve().parents[1]
#: Seconds recorded from the start of each learning move (the ring-down after it).
RECORD_S = 10.0


def tapered_two_link() -> ArmConfig:
    """A vertical two-link arm whose links taper (EI and mass falling toward their ends)."""
    segments = 10
    fall = np.linspace(1.0, 0.55, segments)
    links = [
        {
            'length_m': 1.0,
            'n_segments': segments,
            'ei_nm2': (900.0 * fall).tolist(),
            'mass_kg': (0.16 * fall).tolist(),
            'damping_beta': 5e-4,
        },
        {
            'length_m': 0.8,
            'n_segments': segments,
            'ei_nm2': (380.0 * fall).tolist(),
            'mass_kg': (0.08 * fall).tolist(),
            'damping_beta': 5e-4,
            'joint_mass_kg': 0.8,
        },
    ]
    return arm_from_mapping({'arm': {'plane': 'vertical', 'payload_kg': 0.3, 'links': links}}, '')


@dataclass(frozen=True)
class WorkspaceCase:
    """An arm to learn and the moves to shape on it.

    Attributes:
        name: For the table.
        truth: The arm (MuJoCo runs it; the bags are recorded from it).
        learn: The final angles of the three learning moves, rad.
        finish: The quick step that ends each learning move, rad per joint.
        moves: ``(start, end, duration_s)`` of each move shaped.
    """

    name: str
    truth: ArmConfig
    learn: tuple[tuple[float, ...], ...]
    finish: tuple[float, ...]
    moves: tuple[tuple[tuple[float, ...], tuple[float, ...], float], ...]


def cases() -> dict[str, WorkspaceCase]:
    """The two arms: the tapered two-link arm and ``config/arm_3link.yaml``."""
    return {
        'two_link': WorkspaceCase(
            'two_link',
            tapered_two_link(),
            ((0.3, -0.4), (-0.4, 1.0), (0.8, 0.6)),
            (0.0, 0.03),
            (
                ((0.0, -1.3), (0.3, 1.3), 0.6),
                ((0.5, 1.0), (-0.5, -1.0), 0.5),
                ((0.0, 0.0), (0.6, -0.4), 1.5),
                ((0.3, 1.3), (-0.2, 0.2), 0.4),
                ((-0.5, -1.0), (1.0, 0.8), 1.0),
            ),
        ),
        'three_link': WorkspaceCase(
            'three_link',
            load_arm_config(ROOT / 'config' / 'arm_3link.yaml'),
            ((0.3, -0.4, 0.2), (0.8, 0.5, -0.6), (-0.5, 1.0, 0.4)),
            (0.0, 0.0, 0.03),
            (
                ((0.0, 0.5, -0.5), (0.8, -0.6, 0.9), 1.0),
                ((0.8, -0.6, 0.9), (-0.3, 0.9, -0.2), 0.8),
                ((0.0, 0.0, 0.0), (0.4, 0.3, 0.3), 2.0),
            ),
        ),
    }


def learned_arm(case: WorkspaceCase, folder: Path, seed: int) -> tuple[ArmConfig, ArmConfig]:
    """The nominal arm 20 % off, and the arm learned from three ring-down bags of the truth."""
    rng = np.random.default_rng(seed)
    nominal = replace(nominal_arm(case.truth, rng), source='nominal')
    campaign = ArmCase(case.name, folder, case.learn, case.truth.n_joints, case.finish)
    bags = []
    for k, q in enumerate(case.learn):
        path = folder / f'{case.name}_{k}'
        options = ArmSynthOptions(RECORD_S, seed=seed * 1009 + k, markers_rate_hz=0.0)
        write_arm_bag(path, case.truth, campaign_move(campaign, np.asarray(q)), options)
        bags.append(path)
    observations = bag_observations(bags, nominal, IdentifierConfig())
    return nominal, replace(LinkParameterFit(nominal).fit(observations).arm, source='learned')


@dataclass(frozen=True)
class MoveRow:
    """One move's residuals, m, and the time the shaping added, s."""

    label: str
    unshaped: float
    untuned: float
    tuned: float
    predicted_tuned: float
    added_s: float
    tune_cpu_s: float

    @property
    def untuned_reduction(self) -> float:
        """``1 - untuned / unshaped`` in MuJoCo."""
        return 1.0 - self.untuned / self.unshaped

    @property
    def tuned_reduction(self) -> float:
        """``1 - tuned / unshaped`` in MuJoCo."""
        return 1.0 - self.tuned / self.unshaped


def shaped_rows(case: WorkspaceCase, learned: ArmConfig) -> list[MoveRow]:
    """Every move of the case shaped by the learned arm and run on the truth in MuJoCo."""
    rows = []
    untuned_shaper = WorkspaceShaper(learned, 'zvd', 2)
    tuned_shaper = WorkspaceShaper(learned, 'zvd', 2, tune=True)
    for start, end, duration in case.moves:
        move = minimum_jerk(np.asarray(start), np.asarray(end), duration)
        untuned = untuned_shaper.shape_move(move)
        cpu = time.process_time()
        tuned = tuned_shaper.shape_move(move)
        cpu = time.process_time() - cpu
        unshaped, untuned_m, tuned_m = (
            mujoco_residual(case.truth, trajectory, WINDOW_S)
            for trajectory in (
                move,
                shape_trajectory(move, untuned.impulses),
                shape_trajectory(move, tuned.impulses),
            )
        )
        label = f'{list(start)} -> {list(end)} in {duration:g} s'
        rows.append(
            MoveRow(
                label,
                unshaped,
                untuned_m,
                tuned_m,
                tuned.predicted_residual_shaped_m,
                tuned.impulses.duration_s,
                cpu,
            )
        )
    return rows


def table(name: str, rows: Sequence[MoveRow]) -> list[str]:
    """The rows as text, then the reductions' least and median."""
    lines = [
        f'{name}: residual vibration in MuJoCo (RMS over the 3 s after each move, mm)',
        f'  {"move":<44} {"unshaped":>9} {"ZVD":>8} {"tuned":>8} {"ZVD less":>9} '
        f'{"tuned less":>10} {"model tuned":>11} {"added s":>8} {"tune cpu s":>10}',
    ]
    for row in rows:
        lines.append(
            f'  {row.label:<44} {1e3 * row.unshaped:9.3f} {1e3 * row.untuned:8.4f} '
            f'{1e3 * row.tuned:8.4f} {100 * row.untuned_reduction:8.2f}% '
            f'{100 * row.tuned_reduction:9.2f}% {1e3 * row.predicted_tuned:11.5f} '
            f'{row.added_s:8.3f} {row.tune_cpu_s:10.2f}'
        )
    tuned = [row.tuned_reduction for row in rows]
    untuned = [row.untuned_reduction for row in rows]
    lines.append(
        f'  reduction, least / median: ZVD {100 * min(untuned):.2f} % / '
        f'{100 * statistics.median(untuned):.2f} %, tuned {100 * min(tuned):.2f} % / '
        f'{100 * statistics.median(tuned):.2f} %'
    )
    return lines


def main(argv: Sequence[str] | None = None) -> int:
    """Learns each arm, shapes its moves, prints the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--arms', nargs='+', choices=sorted(cases()), default=sorted(cases()))
    parser.add_argument('--seed', type=int, default=0)
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as folder:
        for name in args.arms:
            case = cases()[name]
            nominal, learned = learned_arm(case, Path(folder), args.seed)
            print(f'{name}: links learned from {len(case.learn)} ring-downs, nominal 20 % off')
            for i, (n, fit, truth) in enumerate(
                zip(nominal.links, learned.links, case.truth.links, strict=True), start=1
            ):
                k = [float(link.spring_stiffness()[0]) for link in (n, fit, truth)]
                print(
                    f'  link {i}: clamp spring nominal {k[0] / k[2] - 1:+.1%} off, learned '
                    f'{k[1] / k[2] - 1:+.3%}'
                )
            print('\n'.join(table(name, shaped_rows(case, learned))))
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
