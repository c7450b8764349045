"""How well several modes are identified, and whether their standard deviations hold.

Each scenario is simulated once without noise by the product's own nonlinear models (the
clamped beam's drop test, an arm moved along a minimum-jerk trajectory); every trial adds
20 micrometres of white noise with its own seed to the tip's x and z and identifies the free
vibration exactly as ``lumpbeam analyze`` (``--arm``) does. The truth is the models' linear
modes about the final rest, which the identifier never sees: the unloaded beam's
(:func:`~lumpbeam_ros.core.model.modes.chain_modes`), the arm's at its final joint angles
(:func:`~lumpbeam_ros.core.model.arm.statics.arm_modes`, ``lumpbeam modes``).

Per scenario and truth mode it prints how often the mode was found, the relative errors of
frequency and damping ratio over the trials that found it (RMS with the bias in it, bias,
std, max) and the coverage: the fraction of those trials whose truth lies within 3 of the
reported standard deviations. Run::

    python -m lumpbeam_lab.ident.modes_accuracy --trials 200
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from lumpbeam_ros.base.resources import config_path
from lumpbeam_ros.core.bagio.series import JointSeries
from lumpbeam_ros.core.ident.bag_analysis import identify_ring_down
from lumpbeam_ros.core.ident.identification import Identification
from lumpbeam_ros.core.ident.identify import identify
from lumpbeam_ros.core.ident.samples import clean_loads, clean_window
from lumpbeam_ros.core.ident.settings import IdentifierConfig
from lumpbeam_ros.core.model.arm.config import load_arm_config
from lumpbeam_ros.core.model.arm.drive import SampledMotion
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.simulate import simulate_arm
from lumpbeam_ros.core.model.arm.statics import arm_modes
from lumpbeam_ros.core.model.chain import LumpedChain
from lumpbeam_ros.core.model.modes import chain_modes
from lumpbeam_ros.core.model.parameters import BeamParameters, DropTestConfig
from lumpbeam_ros.core.model.simulate import simulate_drop_test

RATE_HZ = 180.0
NOISE_M = 20e-6
#: A reported mode is the truth mode within this relative frequency distance.
MATCH_REL = 0.05
#: Coverage is counted at this many standard deviations.
SIGMAS = 3.0


@dataclass(frozen=True)
class Record:
    """One noise-free record and the truth of its modes.

    Attributes:
        name: The scenario.
        t: Stamps, s.
        x: Tip x, m.
        z: Tip z, m.
        truth: ``(natural frequency Hz, damping ratio)`` of each truth mode scored.
        identify: Identifies a noisy copy ``(x, z)`` of the record.
    """

    name: str
    t: np.ndarray
    x: np.ndarray
    z: np.ndarray
    truth: tuple[tuple[float, float], ...]
    identify: Callable[[np.ndarray, np.ndarray], Identification]


def minimum_jerk(
    start: Sequence[float], end: Sequence[float], duration_s: float
) -> JointTrajectory:
    """A rest-to-rest minimum-jerk move sampled at 1 kHz."""
    t = np.arange(round(duration_s * 1000.0) + 1) / 1000.0
    s = t / duration_s
    path = 10 * s**3 - 15 * s**4 + 6 * s**5
    return JointTrajectory(t, np.asarray(start) + np.outer(path, np.subtract(end, start)))


def drop_record(name: str, tip_mass_kg: float, load_kg: float, modes: int) -> Record:
    """The clamped beam's drop test (release at 2 s, 12 s) with the given tip body.

    Args:
        name: The scenario's name.
        tip_mass_kg: The body mounted at the tip (the paper's 2.5 kg hides mode 2).
        load_kg: The load released.
        modes: How many truth modes to score.
    """
    beam = replace(BeamParameters(), tip_mass_kg=tip_mass_kg)
    drop = DropTestConfig(load_kg, 2.0, 12.0)
    exact = simulate_drop_test(beam, drop, RATE_HZ)
    linear = chain_modes(LumpedChain.from_beam(beam, 0.0))
    truth = tuple(
        (float(linear.natural_frequency_hz[k]), float(linear.damping_ratio[k]))
        for k in range(modes)
    )
    loads = clean_loads(np.array([0.0, drop.release_time_s]), np.array([load_kg, 0.0]))
    config = IdentifierConfig(max_fit_s=math.inf)

    def run(x: np.ndarray, z: np.ndarray) -> Identification:
        window = clean_window(exact.t, z, exact.pitch, loads, x=x)
        return identify(window, beam, config, strict=True)

    return Record(name, exact.t, exact.x, exact.z, truth, run)


def arm_record(
    name: str, file: str, move: JointTrajectory, duration_s: float, modes: int
) -> Record:
    """An arm moved along ``move`` and left to ring for the rest of ``duration_s``.

    Args:
        name: The scenario's name.
        file: The arm file under ``config/``.
        move: The joints' trajectory.
        duration_s: The record's length, s.
        modes: How many truth modes to score.
    """
    arm = load_arm_config(config_path(file))
    model = ArmModel.from_config(arm)
    t = np.arange(int(duration_s * RATE_HZ) + 1) / RATE_HZ
    motion = simulate_arm(model, SampledMotion(move), t)
    linear = arm_modes(model, move.angles_rad[-1])
    truth = tuple(
        (float(linear.natural_frequency_hz[k]), float(linear.damping_ratio[k]))
        for k in range(modes)
    )
    joints = JointSeries(t, motion.q, move.joint_names)
    config = IdentifierConfig(max_fit_s=math.inf)
    beam = BeamParameters()

    def run(x: np.ndarray, z: np.ndarray) -> Identification:
        window = clean_window(t, z, motion.tip_pitch, x=x)
        return identify_ring_down(window, joints, beam, config)[0]

    return Record(name, t, motion.tip_x, motion.tip_z, truth, run)


def scenarios() -> list[Callable[[], Record]]:
    """The scenarios scored: two drop tests and two arms' ring-downs."""
    return [
        lambda: drop_record('drop_paper_beam', 2.5, 4.5, 1),
        lambda: drop_record('drop_light_tip', 0.5, 4.5, 2),
        # 0.1 rad: a half radian in 0.4 s rings far enough into the link's nonlinearity to
        # bias the first mode's damping against the linear truth (doc/validation.md).
        lambda: arm_record('rotary', 'arm_rotary.yaml', minimum_jerk([0.0], [0.1], 0.4), 12.4, 2),
        lambda: arm_record(
            'three_link',
            'arm_3link.yaml',
            minimum_jerk([0.0, 0.0, 0.0], [0.01, -0.01, 0.01], 0.6),
            12.6,
            2,
        ),
    ]


@dataclass
class ModeScore:
    """The trials' results for one truth mode."""

    frequency_error: list[float]
    frequency_z: list[float]
    damping_error: list[float]
    damping_z: list[float]

    def add(self, found: tuple[float, float, float, float], truth: tuple[float, float]) -> None:
        """Adds one trial's ``(f, f_std, zeta, zeta_std)`` against ``(f, zeta)`` of the truth."""
        f, f_std, zeta, zeta_std = found
        self.frequency_error.append(f / truth[0] - 1.0)
        self.frequency_z.append((f - truth[0]) / f_std)
        self.damping_error.append(zeta / truth[1] - 1.0)
        self.damping_z.append((zeta - truth[1]) / zeta_std)


def _stats(errors: list[float]) -> str:
    e = np.asarray(errors)
    if e.size == 0:
        return 'n/a'
    rms = math.sqrt(float(np.mean(e * e)))
    return (
        f'rms {100 * rms:.4f} %, bias {100 * float(e.mean()):+.4f} %, '
        f'std {100 * float(e.std()):.4f} %, max {100 * float(np.max(np.abs(e))):.4f} %'
    )


def _coverage(z: list[float]) -> str:
    values = np.abs(np.asarray(z))
    if values.size == 0:
        return 'n/a'
    inside = int(np.count_nonzero(values <= SIGMAS))
    return f'{inside}/{values.size} = {100.0 * inside / values.size:.1f} %'


def score(record: Record, trials: int, first_seed: int = 0) -> list[str]:
    """Runs the trials of one record and returns its report lines."""
    scores = [ModeScore([], [], [], []) for _ in record.truth]
    extra = 0
    failed = 0
    start = time.perf_counter()
    for seed in range(first_seed, first_seed + trials):
        rng = np.random.default_rng(seed)
        x = record.x + rng.normal(0.0, NOISE_M, record.t.size)
        z = record.z + rng.normal(0.0, NOISE_M, record.t.size)
        try:
            result = record.identify(x, z)
        except Exception:  # noqa: BLE001 - a trial that fails is counted, not fatal
            failed += 1
            continue
        matched = set()
        for mode in result.modes:
            f = mode.natural_frequency_hz.value
            near = [
                k for k, (f_true, _) in enumerate(record.truth) if abs(f / f_true - 1) < MATCH_REL
            ]
            if not near:
                extra += 1
                continue
            k = near[0]
            matched.add(k)
            scores[k].add(
                (
                    f,
                    mode.natural_frequency_hz.std,
                    mode.damping_ratio.value,
                    mode.damping_ratio.std,
                ),
                record.truth[k],
            )
    seconds = time.perf_counter() - start
    lines = [
        f'{record.name}: {trials} trials (seeds {first_seed}..{first_seed + trials - 1}), '
        f'{failed} failed, {extra} reported modes matching no truth mode, '
        f'{1e3 * seconds / max(trials, 1):.0f} ms per trial'
    ]
    for k, ((f_true, zeta_true), s) in enumerate(zip(record.truth, scores, strict=True), 1):
        found = len(s.frequency_error)
        lines += [
            f'  mode {k}: truth {f_true:.5f} Hz, damping ratio {zeta_true:.5g}; found in '
            f'{found}/{trials} trials',
            f'    frequency: {_stats(s.frequency_error)}; within {SIGMAS:g} sigma: '
            f'{_coverage(s.frequency_z)}',
            f'    damping:   {_stats(s.damping_error)}; within {SIGMAS:g} sigma: '
            f'{_coverage(s.damping_z)}',
        ]
    return lines


def main(argv: Sequence[str] | None = None) -> int:
    """Prints the accuracy and coverage of every scenario."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--trials', type=int, default=200, help='noise seeds per scenario')
    parser.add_argument('--only', nargs='*', help='scenario names to run (default: all)')
    args = parser.parse_args(argv)
    if args.trials < 1:
        parser.error('--trials must be 1 or more')
    for make in scenarios():
        record = make()
        if args.only and record.name not in args.only:
            continue
        print('\n'.join(score(record, args.trials)), flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
