"""How well ``--fit-links`` recovers an arm's links: seeded trials scored against the truth.

The truth is an arm file (``config/arm_rotary.yaml``, ``config/arm_3link.yaml``); the fit
starts from a nominal arm whose every stiffness and damping is 20 % off (up or down, drawn
per link and trial). The measured modes are the truth's modes at several final joint
configurations with noise drawn from their standard deviations: mode k (from 1) has
``0.1 % x k`` of its frequency and ``5 % x k`` of its damping ratio, the accuracy multi-mode
identification is asked for (frequencies within 0.3 %, damping ratios within 10 %).

``python -m lumpbeam_lab.arm_links`` prints, per link, the truth, the RMS error with its
bias, std and largest value, the mean reported std, and how many trials have the truth within
3 reported stds. ``--bags N`` scores the whole path the same way over N seeded campaigns:
synthetic bags (the truth moved to each configuration and left to ring, 20 um of noise), their
ring-down modes as ``lumpbeam analyze`` identifies them, the fit from a nominal arm 20 % off.

Each campaign move is a 2 s minimum-jerk move that stops short of its configuration by the
case's ``finish`` step, and after half a second at rest that step in 0.15 s: the smooth move
alone leaves modes 2 and 3 of the three-link arm too weak to measure their damping, and a
faster whole move rings mode 1 so hard that its frequency and damping depart from the
linearized model's. A short quick step of the wrist rings every mode a little.
"""

from __future__ import annotations

import argparse
import math
import shutil
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from lumpbeam_ros.core.ident.arm.link_fit import (
    LinkFit,
    LinkParameterFit,
    MeasuredMode,
    ModeObservation,
    link_stiffness_total,
    scaled_arm,
)
from lumpbeam_ros.core.model.arm.config import ArmConfig, load_arm_config
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.statics import arm_modes

ROOT = Path(__file__).resolve().parents[1]
#: The nominal values' error: every stiffness and damping off by this fraction.
NOMINAL_ERROR = 0.2
#: Relative standard deviation of mode k's frequency and damping ratio, times k.
FREQUENCY_STD = 1e-3
DAMPING_STD = 0.05
#: The campaign's moves: the main move's duration, the rest before the finishing step and
#: the step's duration, s; the record's length from the start of the move, s.
MOVE_S = 2.0
PAUSE_S = 0.5
FINISH_S = 0.15
RECORD_S = 10.0


@dataclass(frozen=True)
class ArmCase:
    """An arm, the configurations its moves end in, and the modes seen after each.

    Attributes:
        name: For the table.
        config: The arm file (the truth).
        finals: Final joint angles of each move, rad.
        n_modes: Modes measured per move (the lowest).
        finish: The quick step each bag's move ends with, rad per joint (empty: none).
    """

    name: str
    config: Path
    finals: tuple[tuple[float, ...], ...]
    n_modes: int
    finish: tuple[float, ...] = ()


CASES = (
    ArmCase('rotary', ROOT / 'config' / 'arm_rotary.yaml', ((1.0,), (-0.5,)), 2, (0.03,)),
    ArmCase(
        'three_link',
        ROOT / 'config' / 'arm_3link.yaml',
        (
            (0.3, -0.4, 0.2),
            (0.8, 0.5, -0.6),
            (-0.5, 1.0, 0.4),
            (1.2, -0.8, 0.9),
            (0.0, 0.6, -1.0),
        ),
        3,
        (0.0, 0.0, 0.03),
    ),
)


def observations(
    truth: ArmConfig, case: ArmCase, rng: np.random.Generator | None
) -> list[ModeObservation]:
    """The truth's modes at each final configuration, noisy when ``rng`` is given."""
    model = ArmModel.from_config(truth)
    out = []
    for q in case.finals:
        modes = arm_modes(model, np.asarray(q))
        measured = []
        for k in range(case.n_modes):
            f, zeta = modes.natural_frequency_hz[k], modes.damping_ratio[k]
            f_std, z_std = FREQUENCY_STD * (k + 1) * f, DAMPING_STD * (k + 1) * zeta
            noise = rng.standard_normal(2) if rng is not None else np.zeros(2)
            measured.append(
                MeasuredMode(f + f_std * noise[0], f_std, zeta + z_std * noise[1], z_std)
            )
        out.append(ModeObservation(np.asarray(q, dtype=float), tuple(measured), str(q)))
    return out


def nominal_arm(truth: ArmConfig, rng: np.random.Generator) -> ArmConfig:
    """The truth with every stiffness and damping ``NOMINAL_ERROR`` off, up or down."""
    n = truth.n_joints
    signs = rng.choice([-1.0, 1.0], size=(2, n))
    factors = 1.0 + NOMINAL_ERROR * signs
    betas = np.array([link.damping_beta for link in truth.links]) * factors[1]
    return scaled_arm(truth, factors[0], betas)


def truth_table(truth: ArmConfig) -> np.ndarray:
    """(n_links, 2): each link's k_tE and damping_beta."""
    return np.array([[link_stiffness_total(link), link.damping_beta] for link in truth.links])


def fit_table(fit: LinkFit) -> tuple[np.ndarray, np.ndarray]:
    """(n_links, 2) values and stds, as :func:`truth_table`."""
    values = np.array([[e.k_total_nm_per_rad, e.damping_beta] for e in fit.links])
    stds = np.array([[e.k_total_nm_per_rad_std, e.damping_beta_std] for e in fit.links])
    return values, stds


@dataclass(frozen=True)
class Trials:
    """Seeded trials of one arm.

    Attributes:
        truth: (n_links, 2) true k_tE and beta.
        values: (trials, n_links, 2) fitted.
        stds: (trials, n_links, 2) reported standard deviations.
    """

    truth: np.ndarray
    values: np.ndarray
    stds: np.ndarray

    def rows(self) -> list[str]:
        """One line per link and quantity: errors in % of the truth, coverage."""
        lines = []
        trials = self.values.shape[0]
        for i in range(self.truth.shape[0]):
            for j, name in enumerate(('k_total', 'beta')):
                truth = self.truth[i, j]
                err = (self.values[:, i, j] - truth) / truth * 100
                inside = int(
                    np.sum(np.abs(self.values[:, i, j] - truth) <= 3 * self.stds[:, i, j])
                )
                lines.append(
                    f'  link {i + 1} {name:7s} truth {truth:10.5g}  error % RMS {_rms(err):6.3f} '
                    f'bias {err.mean():+6.3f} std {err.std():6.3f} max {np.abs(err).max():6.3f}'
                    f'  mean std % {np.mean(self.stds[:, i, j]) / truth * 100:6.3f}'
                    f'  within 3 std {inside}/{trials}'
                )
        return lines


def _rms(values: np.ndarray) -> float:
    return float(math.sqrt(np.mean(values**2)))


def run_trials(case: ArmCase, trials: int, seed: int = 0) -> Trials:
    """Fits ``trials`` noisy measurements from as many nominal arms 20 % off."""
    truth = load_arm_config(case.config)
    rng = np.random.default_rng(seed)
    values, stds = [], []
    for _ in range(trials):
        fit = LinkParameterFit(nominal_arm(truth, rng)).fit(observations(truth, case, rng))
        v, s = fit_table(fit)
        values.append(v)
        stds.append(s)
    return Trials(truth_table(truth), np.array(values), np.array(stds))


def campaign_move(case: ArmCase, q: np.ndarray) -> JointTrajectory:
    """The move of one bag: from zero to ``q``, ending with the case's quick finishing step."""
    from lumpbeam_lab.shaping_loop import minimum_jerk

    finish = np.asarray(case.finish, dtype=float) if case.finish else np.zeros(q.size)
    move = minimum_jerk(np.zeros(q.size), q - finish, MOVE_S)
    if not case.finish:
        return move
    step = minimum_jerk(q - finish, q, FINISH_S)
    return JointTrajectory(
        np.concatenate([move.time_s, MOVE_S + PAUSE_S + step.time_s]),
        np.vstack([move.angles_rad, step.angles_rad]),
    )


@dataclass(frozen=True)
class BagTrials:
    """Seeded campaigns of one arm, from bags: the fits and what the bags gave.

    Attributes:
        trials: The fits scored as :class:`Trials`.
        modes: Modes identified per campaign (all bags).
        reduced_chi2: Each campaign's chi-square over its degrees of freedom.
        mode_errors: For each mode number (1-based) the fit matched a measured mode to, rows
            of (frequency error, its reported std, damping-ratio error, its reported std),
            relative to the truth's mode at the bag's final angles.
        bags: Bags per campaign.
    """

    trials: Trials
    modes: np.ndarray
    reduced_chi2: np.ndarray
    mode_errors: dict[int, np.ndarray]
    bags: int

    def mode_rows(self) -> list[str]:
        """One line per mode: how well the ring-downs measured it, in % of the truth."""
        lines = []
        campaigns = self.modes.size
        for k, rows in sorted(self.mode_errors.items()):
            err = rows * 100
            inside = [int(np.sum(np.abs(err[:, i]) <= 3 * err[:, i + 1])) for i in (0, 2)]
            lines.append(
                f'  mode {k} in {len(rows)}/{self.bags * campaigns} bags: frequency error % '
                f'RMS {_rms(err[:, 0]):.4f} mean std % {err[:, 1].mean():.4f} within 3 std '
                f'{inside[0]}; damping ratio error % RMS {_rms(err[:, 2]):.2f} bias '
                f'{err[:, 2].mean():+.2f} mean std % {err[:, 3].mean():.2f} within 3 std '
                f'{inside[1]}'
            )
        return lines


def run_bag_trials(case: ArmCase, folder: Path, trials: int, seed: int = 0) -> BagTrials:
    """The whole path ``trials`` times: noisy bags, their ring-down modes, the fit.

    Each campaign draws new measurement noise for its bags and a new nominal arm 20 % off.
    """
    from lumpbeam_ros.core.ident.arm.bag_modes import bag_observations
    from lumpbeam_ros.core.ident.settings import IdentifierConfig
    from lumpbeam_ros.core.synthetic.arm_bag import ArmSynthOptions, write_arm_bag

    truth = load_arm_config(case.config)
    rng = np.random.default_rng(seed)
    moves = [campaign_move(case, np.asarray(q, dtype=float)) for q in case.finals]
    values, stds, modes, chi2 = [], [], [], []
    errors: dict[int, list[list[float]]] = {}
    truth_model = ArmModel.from_config(truth)
    for trial in range(trials):
        bags = []
        for k, move in enumerate(moves):
            path = folder / f'{case.name}_{trial}_{k}'
            options = ArmSynthOptions(RECORD_S, seed=seed * 100_003 + trial * 101 + k)
            write_arm_bag(path, truth, move, replace(options, markers_rate_hz=0.0))
            bags.append(path)
        obs = bag_observations(bags, truth, IdentifierConfig())
        for path in bags:
            shutil.rmtree(path)
        fit = LinkParameterFit(nominal_arm(truth, rng)).fit(obs)
        v, s = fit_table(fit)
        values.append(v)
        stds.append(s)
        modes.append(sum(len(o.modes) for o in obs))
        chi2.append(fit.chi2 / fit.dof if fit.dof > 0 else math.nan)
        for o, match in zip(obs, fit.matches, strict=True):
            want = arm_modes(truth_model, o.joint_angles_rad)
            for m, j in zip(o.sorted_modes(), match, strict=True):
                f, zeta = want.natural_frequency_hz[j], want.damping_ratio[j]
                errors.setdefault(j + 1, []).append(
                    [
                        m.natural_frequency_hz / f - 1,
                        m.natural_frequency_hz_std / f,
                        m.damping_ratio / zeta - 1,
                        m.damping_ratio_std / zeta,
                    ]
                )
    return BagTrials(
        Trials(truth_table(truth), np.array(values), np.array(stds)),
        np.array(modes),
        np.array(chi2),
        {k: np.array(rows) for k, rows in errors.items()},
        len(moves),
    )


def main(argv: Sequence[str] | None = None) -> int:
    """Prints the trials' table (and with ``--bags`` the whole path's)."""
    parser = argparse.ArgumentParser(prog='python -m lumpbeam_lab.arm_links')
    parser.add_argument(
        '--trials', type=int, default=100, help='seeded trials per arm (100; 0: none)'
    )
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--only', choices=[c.name for c in CASES], help='one arm')
    parser.add_argument(
        '--repeat',
        type=int,
        default=1,
        metavar='N',
        help='the trials measure each configuration N times (1): how much data a looser '
        'identification needs',
    )
    parser.add_argument(
        '--smooth',
        action='store_true',
        help='campaign moves without the finishing step (what it is for)',
    )
    parser.add_argument(
        '--bags',
        type=int,
        default=0,
        metavar='N',
        help='also N seeded campaigns of the whole path from synthetic bags (0: none)',
    )
    args = parser.parse_args(argv)
    if args.repeat < 1:
        parser.error(f'--repeat {args.repeat}: at least 1')
    for case in CASES:
        if args.only and case.name != args.only:
            continue
        if args.trials > 0:
            repeated = replace(case, finals=case.finals * args.repeat)
            result = run_trials(repeated, args.trials, args.seed)
            print(
                f'{case.name}: {len(case.finals)} configurations x {case.n_modes} modes'
                f'{f", each in {args.repeat} bags" if args.repeat > 1 else ""}, '
                f'nominal {NOMINAL_ERROR:.0%} off, {args.trials} trials'
            )
            print('\n'.join(result.rows()))
        if args.bags > 0:
            if args.smooth:
                case = replace(case, finish=())
            with tempfile.TemporaryDirectory() as folder:
                bag_result = run_bag_trials(case, Path(folder), args.bags, args.seed)
            step = f', ending with a {FINISH_S:g} s step of {list(case.finish)} rad' * bool(
                case.finish
            )
            print(
                f'{case.name} from bags: {len(case.finals)} bags of {RECORD_S:g} s '
                f'({MOVE_S:g} s moves{step}), nominal {NOMINAL_ERROR:.0%} off, '
                f'{args.bags} campaigns: modes identified {bag_result.modes.min()}'
                f'-{bag_result.modes.max()}, reduced chi2 median '
                f'{np.median(bag_result.reduced_chi2):.3g} max {bag_result.reduced_chi2.max():.3g}'
            )
            print('\n'.join(bag_result.trials.rows()))
            print('\n'.join(bag_result.mode_rows()))
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
