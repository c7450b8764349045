"""Shaped moves on the arm: the residual vibration left, in the arm's model and in MuJoCo.

A rest-to-rest minimum-jerk move, sampled at 1 kHz as a trajectory file holds it, is shaped
with ZV, ZVD or EI designed for the modes the arm's linearization gives at the move's final
angles (:func:`~lumpbeam_ros.core.model.arm.statics.arm_modes`), at the exact frequency or 15 %
off. Unshaped and shaped moves are simulated by the arm's model
(:func:`~lumpbeam_ros.core.model.arm.simulate.simulate_arm`) and by the independent MuJoCo model of
the arm's tests (lumpbeam_lab/mujoco_arm.py: its own bodies, hinges, mass matrix and RK4), each
driven by the same spline of the samples. The residual vibration is the RMS of the tip's
distance from its final rest (each model's own static equilibrium) over the 3 s after the
move ends (the shaped move ends later, by the shaper's duration).

Targets (reduction against the unshaped move, in both models): ZV at the exact mode 90 %,
ZVD 95 %, EI 90 % (it leaves 5 % by design), ZVD and EI with the frequency 15 % off 85 %; on
the three-link arm a shaper for its first two modes 90 %.

``pytest test/core/shaping/test_on_arm.py -m slow -q -s -n0`` prints the table.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from lumpbeam_lab.mujoco_arm import mujoco_residual
from lumpbeam_ros.core.model.arm.config import ArmConfig, load_arm_config
from lumpbeam_ros.core.model.arm.drive import SampledMotion
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.residual import WINDOW_S, arm_residual
from lumpbeam_ros.core.model.arm.simulate import simulate_arm
from lumpbeam_ros.core.model.arm.statics import arm_modes
from lumpbeam_ros.core.shaping.apply import shape_trajectory
from lumpbeam_ros.core.shaping.impulses import Mode
from lumpbeam_ros.core.shaping.shapers import design_shaper

pytestmark = pytest.mark.slow  # a validation matrix: minutes of CPU

CONFIG = Path(__file__).resolve().parents[3] / 'config'

#: Sample interval of the move (a trajectory file at 1 kHz), s.
STEP_S = 1e-3

#: Sample interval of the simulated tip, s (a few hundred samples per period of the modes).
OUTPUT_S = 2e-3

#: The arms' moves: (file, start angles, end angles, duration s, modes shaped). The rotary
#: link (first mode 3.5 Hz, period 0.29 s) turns 1 rad in 0.3 s; the three-link arm (modes
#: 1.2 and 6.8 Hz at the end) moves all joints in 1 s, lifting against gravity.
ARMS = {
    'rotary': ('arm_rotary.yaml', [0.0], [1.0], 0.3, 1),
    'three_link': ('arm_3link.yaml', [0.0, 0.0, 0.0], [0.3, -0.4, 0.2], 1.0, 2),
}

#: (arm, shaper, design frequency / true frequency, least reduction).
CASES = [
    ('rotary', 'zv', 1.0, 0.90),
    ('rotary', 'zvd', 1.0, 0.95),
    ('rotary', 'ei', 1.0, 0.90),
    ('rotary', 'zvd', 0.85, 0.85),
    ('rotary', 'zvd', 1.15, 0.85),
    ('rotary', 'ei', 0.85, 0.85),
    ('rotary', 'ei', 1.15, 0.85),
    ('three_link', 'zv', 1.0, 0.90),
]


def minimum_jerk(start: np.ndarray, end: np.ndarray, duration: float) -> JointTrajectory:
    """A rest-to-rest minimum-jerk move from ``start`` to ``end``, sampled every ``STEP_S``."""
    t = np.arange(round(duration / STEP_S) + 1) * STEP_S
    s = t / duration
    path = 10 * s**3 - 15 * s**4 + 6 * s**5
    return JointTrajectory(t, start + np.outer(path, end - start))


@dataclass(frozen=True)
class Residuals:
    """The residual vibration of one move in both models, m."""

    ours: float
    mujoco: float


def _simulate(config: ArmConfig, trajectory: JointTrajectory) -> Residuals:
    model = ArmModel.from_config(config)
    motion = SampledMotion(trajectory)
    end = float(trajectory.time_s[-1])
    t = np.arange(round((end + WINDOW_S) / OUTPUT_S) + 1) * OUTPUT_S
    ours = arm_residual(model, simulate_arm(model, motion, t), end)
    # MuJoCo follows the spline simulate_arm integrates a dense trajectory through.
    return Residuals(ours, mujoco_residual(config, trajectory, WINDOW_S, OUTPUT_S))


_UNSHAPED: dict[str, Residuals] = {}
_TABLE: list[str] = []


@pytest.fixture(scope='module', autouse=True)
def table():
    """Prints the reductions once every case has run (with ``-s``)."""
    yield
    head = (
        f'{"arm":<11} {"shaper":<6} {"f/f1":>5}  {"unshaped mm":>11} {"shaped mm":>10} '
        f'{"reduction":>9}  {"MuJoCo unshaped":>15} {"shaped":>8} {"reduction":>9}'
    )
    print('\nResidual vibration, RMS over 3 s after the move:\n' + head)
    print('\n'.join(_TABLE))


def _unshaped(name: str) -> Residuals:
    if name not in _UNSHAPED:
        file, start, end, duration, _ = ARMS[name]
        config = load_arm_config(CONFIG / file)
        _UNSHAPED[name] = _simulate(config, minimum_jerk(np.array(start), np.array(end), duration))
    return _UNSHAPED[name]


@pytest.mark.parametrize(('name', 'kind', 'scale', 'target'), CASES)
def test_shaped_move_rings_less_than_unshaped_in_both_models(name, kind, scale, target):
    file, start, end, duration, count = ARMS[name]
    config = load_arm_config(CONFIG / file)
    modes = arm_modes(ArmModel.from_config(config), np.array(end))
    design = [
        Mode(float(modes.natural_frequency_hz[i]) * scale, float(modes.damping_ratio[i]))
        for i in range(count)
    ]
    move = minimum_jerk(np.array(start), np.array(end), duration)
    shaped = _simulate(config, shape_trajectory(move, design_shaper(kind, design)))
    unshaped = _unshaped(name)
    ours = 1.0 - shaped.ours / unshaped.ours
    theirs = 1.0 - shaped.mujoco / unshaped.mujoco
    label = kind if count == 1 else f'{kind}x{count}'
    _TABLE.append(
        f'{name:<11} {label:<6} {scale:>5.2f}  {unshaped.ours * 1e3:>11.3f} '
        f'{shaped.ours * 1e3:>10.4f} {ours:>9.1%}  {unshaped.mujoco * 1e3:>15.3f} '
        f'{shaped.mujoco * 1e3:>8.4f} {theirs:>9.1%}'
    )
    # The move rings well above the integrators' accuracy (micrometres, test_against_mujoco).
    assert unshaped.ours > 1e-3
    assert unshaped.mujoco == pytest.approx(unshaped.ours, rel=1e-3)
    assert ours >= target
    assert theirs >= target
