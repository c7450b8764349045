"""How well ``--fit-links`` recovers an arm's links: seeded trials scored against the truth.

The truth is an arm file (``config/arm_rotary.yaml``, ``config/arm_3link.yaml``); the fit
starts from a nominal arm whose every stiffness and damping is 20 % off (up or down, drawn
per link and trial). The measured modes are the truth's modes at several final joint
configurations with noise drawn from their standard deviations: mode k (from 1) has
``0.1 % x k`` of its frequency and ``5 % x k`` of its damping ratio, the accuracy multi-mode
identification is asked for (frequencies within 0.3 %, damping ratios within 10 %).

``python -m lumpbeam_lab.arm_links`` prints, per link, the truth, the RMS error with its
bias, std and largest value, the mean reported std, and how many trials have the truth within
3 reported stds. ``--bags`` also runs the whole path once per arm: synthetic bags (the truth
moved to each configuration and left to ring), their ring-down modes, the fit.
"""

from __future__ import annotations

import argparse
import math
import shutil
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lumpbeam_ros.arm.config import ArmConfig, load_arm_config
from lumpbeam_ros.arm.link_fit import (
    LinkFit,
    LinkParameterFit,
    MeasuredMode,
    ModeObservation,
    link_stiffness_total,
    scaled_arm,
)
from lumpbeam_ros.arm.model import ArmModel
from lumpbeam_ros.arm.statics import arm_modes

ROOT = Path(__file__).resolve().parents[1]
#: The nominal values' error: every stiffness and damping off by this fraction.
NOMINAL_ERROR = 0.2
#: Relative standard deviation of mode k's frequency and damping ratio, times k.
FREQUENCY_STD = 1e-3
DAMPING_STD = 0.05


@dataclass(frozen=True)
class ArmCase:
    """An arm, the configurations its moves end in, and the modes seen after each.

    Attributes:
        name: For the table.
        config: The arm file (the truth).
        finals: Final joint angles of each move, rad.
        n_modes: Modes measured per move (the lowest).
    """

    name: str
    config: Path
    finals: tuple[tuple[float, ...], ...]
    n_modes: int


CASES = (
    ArmCase('rotary', ROOT / 'config' / 'arm_rotary.yaml', ((1.0,), (-0.5,)), 2),
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


def run_bags(case: ArmCase, folder: Path, move_s: float = 2.0, record_s: float = 10.0) -> str:
    """The whole path once: bags of the truth's moves, their ring-down modes, the fit.

    Returns:
        The table, one line per link.
    """
    from lumpbeam_lab.shaping_loop import minimum_jerk
    from lumpbeam_ros.arm.bag_modes import bag_observations
    from lumpbeam_ros.synthetic.arm_bag import ArmSynthOptions, write_arm_bag

    truth = load_arm_config(case.config)
    bags = []
    start = np.zeros(truth.n_joints)
    for k, q in enumerate(case.finals):
        path = folder / f'{case.name}_{k}'
        shutil.rmtree(path, ignore_errors=True)
        move = minimum_jerk(start, np.asarray(q, dtype=float), move_s)
        write_arm_bag(path, truth, move, ArmSynthOptions(record_s))
        bags.append(path)
    obs = bag_observations(bags, truth)
    nominal = nominal_arm(truth, np.random.default_rng(1))
    fit = LinkParameterFit(nominal).fit(obs)
    values, stds = fit_table(fit)
    want = truth_table(truth)
    modes = sum(len(o.modes) for o in obs)
    lines = [
        f'{case.name}: {len(bags)} bags, {modes} modes identified, '
        f'chi2/dof {fit.chi2:.3g}/{fit.dof}'
    ]
    for i in range(want.shape[0]):
        for j, name in enumerate(('k_total', 'beta')):
            err = (values[i, j] - want[i, j]) / want[i, j] * 100
            sigmas = abs(values[i, j] - want[i, j]) / stds[i, j]
            lines.append(
                f'  link {i + 1} {name:7s} truth {want[i, j]:10.5g} fit {values[i, j]:10.5g} '
                f'+- {stds[i, j]:8.3g}  error {err:+7.3f} %  ({sigmas:.1f} std)'
            )
    return '\n'.join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    """Prints the trials' table (and with ``--bags`` the whole path's)."""
    parser = argparse.ArgumentParser(prog='python -m lumpbeam_lab.arm_links')
    parser.add_argument(
        '--trials', type=int, default=100, help='seeded trials per arm (100; 0: none)'
    )
    parser.add_argument('--seed', type=int, default=0)
    parser.add_argument('--only', choices=[c.name for c in CASES], help='one arm')
    parser.add_argument('--bags', action='store_true', help='also the whole path from bags')
    args = parser.parse_args(argv)
    for case in CASES:
        if args.only and case.name != args.only:
            continue
        if args.trials > 0:
            result = run_trials(case, args.trials, args.seed)
            print(
                f'{case.name}: {len(case.finals)} configurations x {case.n_modes} modes, '
                f'nominal {NOMINAL_ERROR:.0%} off, {args.trials} trials'
            )
            print('\n'.join(result.rows()))
        if args.bags:
            with tempfile.TemporaryDirectory() as folder:
                print(run_bags(case, Path(folder)))
    return 0


if __name__ == '__main__':
    raise SystemExit(main())
