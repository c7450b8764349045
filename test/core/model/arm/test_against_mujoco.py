"""The arm against MuJoCo: statics, modal frequencies and tip trajectories in motion.

MuJoCo (lumpbeam_lab/mujoco_arm.py) builds the same segments as bodies on hinges in relative
coordinates and computes its own mass matrix, bias forces and gravity; it shares with the
arm only the physical description (lengths, masses, springs, dampers, the ideal servo).

Tolerances, and why:
- statics: 1e-10 rad (both solve the equilibrium by Newton to 1e-12);
- modal frequencies and damping ratios: 1e-6 relative (MuJoCo's linearization is by central
  differences of its accelerations with a 1e-6 step, whose error is ~1e-9 relative);
- tip position, by the arm's LSODA method at rtol 1e-8: RMS difference over the move and
  ring-down below 0.05 um, for tip excursions of 0.1 to 0.7 m. MuJoCo's RK4 at a 1e-4 s step
  errs by about (omega h)^4 / 120 per radian of phase on the fastest retained mode, and holds
  the drive at its midpoint value over each step (second order): a few nanometres here. This
  is the model against MuJoCo's.
- tip position, by the arm's default modal method: RMS below 1 um and the largest below
  5 um. Its hold on a 2 ms grid errs by 0.01 to 0.05 um on these quick moves; this is the
  fast method against the same model. A wrong sign, lever or spring rule shows
  as millimetres in either.

Run with ``-s`` to print the figures.
"""

import numpy as np
import pytest
from arm_cases import small_arm, smooth_move

from lumpbeam_lab.mujoco_arm import MujocoArm
from lumpbeam_ros.core.model.arm.model import ArmModel
from lumpbeam_ros.core.model.arm.simulate import simulate_arm
from lumpbeam_ros.core.model.arm.statics import arm_equilibrium, arm_modes

CASES = {
    # name: (links, joint move, move duration s, record s)
    'rotary': (1, [0.8], 0.6, 1.2),
    'two_link': (2, [0.5, -0.9], 0.7, 1.2),
    'three_link': (3, [-0.4, 0.9, 0.6], 0.8, 1.2),
}


@pytest.mark.parametrize('name', CASES)
def test_statics_and_modes_agree_with_mujoco(name):
    links, amplitude, _, _ = CASES[name]
    config = small_arm(links)
    model = ArmModel.from_config(config)
    mujoco_arm = MujocoArm(config)
    q = np.asarray(amplitude)
    ours = arm_equilibrium(model, q)
    theirs = mujoco_arm.equilibrium(q)
    assert ours == pytest.approx(theirs, abs=1e-10)
    modes = arm_modes(model, q)
    lam = mujoco_arm.modal_eigenvalues()
    lam = lam[lam.imag > 1e-6 * np.abs(lam).max()]
    lam = lam[np.argsort(np.abs(lam))]
    freq = np.abs(lam) / (2 * np.pi)
    zeta = -lam.real / np.abs(lam)
    rel = np.abs(modes.natural_frequency_hz - freq) / freq
    print(
        f'\n{name}: {freq.size} modes, first {freq[0]:.6f} Hz (MuJoCo) vs '
        f'{modes.natural_frequency_hz[0]:.6f} Hz; largest frequency difference '
        f'{rel.max():.2e} relative, damping ratio {np.abs(modes.damping_ratio - zeta).max():.2e}'
    )
    assert modes.natural_frequency_hz == pytest.approx(freq, rel=1e-6)
    assert modes.damping_ratio == pytest.approx(zeta, rel=1e-6, abs=1e-9)


@pytest.mark.parametrize('name', CASES)
def test_tip_trajectory_in_motion_agrees_with_mujoco(name):
    links, amplitude, duration, record = CASES[name]
    config = small_arm(links)
    model = ArmModel.from_config(config)
    move = smooth_move(np.asarray(amplitude), duration)
    mujoco_arm = MujocoArm(config)
    mujoco_arm.equilibrium(move.angles(0.0))
    theirs = mujoco_arm.run(lambda t: (move.angles(t), move.rates(t)), record, 0.01)
    ours = simulate_arm(model, move, theirs['t'])
    gap = np.hypot(ours.tip_x - theirs['x'], ours.tip_z - theirs['z'])
    rms = float(np.sqrt(np.mean(gap**2)))
    stepped = simulate_arm(model, move, theirs['t'], method='lsoda')
    model_gap = np.hypot(stepped.tip_x - theirs['x'], stepped.tip_z - theirs['z'])
    model_rms = float(np.sqrt(np.mean(model_gap**2)))
    excursion = float(np.hypot(np.ptp(ours.tip_x), np.ptp(ours.tip_z)))
    # The ring-down: the vibration about the final rest.
    rest = model.chain.tip_pose(arm_equilibrium(model, move.angles(record)))
    ring = np.hypot(ours.tip_x - rest[0], ours.tip_z - rest[1])[theirs['t'] > duration].max()
    print(
        f'\n{name}: tip excursion {excursion:.3f} m, ring-down amplitude {ring * 1e3:.2f} mm; '
        f'tip difference RMS {rms:.2e} m, max {gap.max():.2e} m, pitch max '
        f'{np.abs(ours.tip_pitch - theirs["pitch"]).max():.2e} rad; by LSODA: RMS '
        f'{model_rms:.2e} m, max {model_gap.max():.2e} m'
    )
    assert model_rms < 5e-8
    assert ring > 1e-4  # the move excites a vibration worth comparing
    assert rms < 1e-6
    assert gap.max() < 5e-6
    assert ours.tip_pitch == pytest.approx(theirs['pitch'], abs=1e-6)
