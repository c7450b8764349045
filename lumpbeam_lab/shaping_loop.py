"""The demo's shaping loop, offline: ring, identify, shape, ring less.

What the live demo is to do with nodes, done here with the same core calls on synthetic
bags, so it runs before the simulator node's arm mode and the multi-mode identifier exist:

1. the arm (an arm file, the truth) moves unshaped and rings: a bag with 20 um of noise;
2. the modes of its ring-down are identified from the bag
   (:mod:`lumpbeam_ros.core.ident.arm.bag_modes`), with their standard deviations;
3. the shaper the shaper node would choose for them (its defaults: ZV, EI when a frequency
   is uncertain by more than 1 %) shapes the move back;
4. the arm moves back shaped (a second bag, from rest where the first ended);
5. each move's residual vibration (the tip's RMS distance from its rest over the 3 s after
   the move ends, from ``/tip_pose_truth``) is printed, and drawn.

``python -m lumpbeam_lab.shaping_loop [--out DIR]`` runs it for the rotary arm and the
three-link arm.
"""

from __future__ import annotations

import argparse
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lumpbeam_ros.base.interface import TIP_POSE_TRUTH
from lumpbeam_ros.core.ident.arm.bag_modes import bag_observation
from lumpbeam_ros.core.ident.arm.link_fit import MeasuredMode
from lumpbeam_ros.core.ident.settings import IdentifierConfig
from lumpbeam_ros.core.model.arm.config import ArmConfig, load_arm_config
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.shaping.apply import shape_trajectory
from lumpbeam_ros.core.shaping.estimate import ModeEstimate, choose_shaper
from lumpbeam_ros.core.shaping.impulses import Impulses, Mode
from lumpbeam_ros.core.shaping.loop import ShapingOutcome, bag_move_residuals
from lumpbeam_ros.core.shaping.shapers import design_shaper
from lumpbeam_ros.core.synthetic.arm_bag import ArmSynthOptions, write_arm_bag
from lumpbeam_ros.nodes.params.shaper_params import SHAPER_SCHEMA

ROOT = Path(__file__).resolve().parents[1]
#: Seconds recorded after each move: the identifier's ring-down and the residual's window.
RECORD_AFTER_S = 6.0


@dataclass(frozen=True)
class LoopCase:
    """An arm and its two moves: out to ``far`` unshaped, back to ``near`` shaped.

    Attributes:
        name: For the table.
        config: The arm file.
        near: Where the arm starts and returns to, rad.
        far: Where the first move ends, rad.
        move_s: Each move's duration before shaping, s.
    """

    name: str
    config: Path
    near: tuple[float, ...]
    far: tuple[float, ...]
    move_s: float


CASES = (
    LoopCase('rotary', ROOT / 'config' / 'arm_rotary.yaml', (0.0,), (1.0,), 0.3),
    LoopCase(
        'three_link', ROOT / 'config' / 'arm_3link.yaml', (0.0, 0.0, 0.0), (0.3, -0.4, 0.2), 1.0
    ),
)


def minimum_jerk(start: np.ndarray, end: np.ndarray, duration_s: float) -> JointTrajectory:
    """A rest-to-rest minimum-jerk move sampled at 1 kHz."""
    t = np.linspace(0.0, duration_s, int(round(duration_s * 1000)) + 1)
    s = t / duration_s
    s = 10 * s**3 - 15 * s**4 + 6 * s**5
    return JointTrajectory(t, start + np.outer(s, end - start))


def shaper_for(modes: Sequence[MeasuredMode]) -> tuple[str, Impulses]:
    """The shaper node's choice for identified modes (its default parameters)."""
    defaults = SHAPER_SCHEMA.defaults()
    max_modes, robust_above = defaults['max_modes'], defaults['robust_above']
    assert isinstance(max_modes, int) and isinstance(robust_above, float)
    estimates = [
        ModeEstimate(
            Mode(m.natural_frequency_hz, m.damping_ratio),
            m.natural_frequency_hz_std,
            m.damping_ratio_std,
        )
        for m in modes[:max_modes]
    ]
    kind = choose_shaper(
        estimates,
        str(defaults['shaper']),
        str(defaults['robust_shaper']),
        robust_above,
    )
    return kind, design_shaper(kind, [e.mode for e in estimates])


def run_loop(case: LoopCase, folder: Path, noise_m: float = 20e-6) -> tuple[str, ShapingOutcome]:
    """Moves out unshaped, identifies, moves back shaped; the report and the outcome."""
    arm: ArmConfig = load_arm_config(case.config)
    near, far = np.asarray(case.near, dtype=float), np.asarray(case.far, dtype=float)
    out = minimum_jerk(near, far, case.move_s)
    first = folder / f'{case.name}_unshaped'
    options = ArmSynthOptions(out.duration_s + RECORD_AFTER_S, noise_m=noise_m)
    write_arm_bag(first, arm, out, options)
    observation = bag_observation(first, arm, IdentifierConfig())
    kind, impulses = shaper_for(observation.sorted_modes())
    back = shape_trajectory(minimum_jerk(far, near, case.move_s), impulses)
    second = folder / f'{case.name}_shaped'
    options = ArmSynthOptions(back.duration_s + RECORD_AFTER_S, noise_m=noise_m, seed=1)
    write_arm_bag(second, arm, back, options)
    (unshaped,) = bag_move_residuals(first, arm, TIP_POSE_TRUTH)
    (shaped,) = bag_move_residuals(second, arm, TIP_POSE_TRUTH)
    outcome = ShapingOutcome(unshaped, shaped)
    identified = ', '.join(
        f'{m.natural_frequency_hz:.4f} +- {m.natural_frequency_hz_std:.2g} Hz '
        f'(zeta {m.damping_ratio:.4f} +- {m.damping_ratio_std:.2g})'
        for m in observation.sorted_modes()
    )
    lines = [
        f'{case.name}: identified {identified}',
        f'  shaper {kind} for {min(len(observation.modes), 2)} mode(s), '
        f'{impulses.duration_s:.3f} s added',
        f'  {outcome.summary()}',
    ]
    return '\n'.join(lines), outcome


def main(argv: Sequence[str] | None = None) -> int:
    """Runs the loop for each arm, prints it and, with ``--out``, draws it."""
    parser = argparse.ArgumentParser(prog='python -m lumpbeam_lab.shaping_loop')
    parser.add_argument(
        '--out', type=Path, help='write the figure of each arm (PNG) into this folder'
    )
    parser.add_argument('--only', choices=[c.name for c in CASES], help='one arm')
    args = parser.parse_args(argv)
    for case in CASES:
        if args.only and case.name != args.only:
            continue
        with tempfile.TemporaryDirectory() as folder:
            report, outcome = run_loop(case, Path(folder))
        print(report)
        if args.out:
            from lumpbeam_ros.apps.plots.shaping import plot_shaping_outcome

            print(f'  wrote {plot_shaping_outcome(outcome, args.out / f"{case.name}_loop.png")}')
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
