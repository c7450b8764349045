"""Draws the README's arm figure: the three-link arm of config/arm_3link.yaml moved and ringing.

Usage (from the repository root)::

    python tools/arm_figure.py [OUT.png]        # default: doc/arm_move.png

It writes a 1 s rest-to-rest cycloidal move of the three joints to a trajectory file,
simulates it into a synthetic bag as ``lumpbeam synth --arm --trajectory`` does (with
``/beam_markers``), and draws snapshots of the markers during and after the move
(:func:`lumpbeam_ros.apps.plots.arm.plot_arm_snapshots`). Everything but the PNG goes to a
temporary folder.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

from lumpbeam_ros.apps.plots.arm import plot_arm_snapshots
from lumpbeam_ros.core.model.arm.config import load_arm_config
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.synthetic.arm_bag import ArmSynthOptions, write_arm_bag

ROOT = Path(__file__).resolve().parents[1]
#: The move: each joint's excursion, rad, over MOVE_S, then the ring-down to RECORD_S.
EXCURSION_RAD = (-0.6, 0.9, 0.7)
MOVE_S = 1.0
RECORD_S = 3.0
#: The instants drawn: the start, during the move, its end and the ring-down.
SNAPSHOTS_S = (0.0, 0.35, 0.6, 1.0, 1.2, 2.5)


def main(argv: list[str]) -> int:
    """Writes the figure and prints where."""
    out = Path(argv[0]) if argv else ROOT / 'doc' / 'arm_move.png'
    t = np.arange(0.0, MOVE_S + 1e-9, 1e-3)
    s = t / MOVE_S
    profile = s - np.sin(2 * np.pi * s) / (2 * np.pi)
    move = JointTrajectory(t, np.outer(profile, EXCURSION_RAD))
    config = load_arm_config(ROOT / 'config' / 'arm_3link.yaml')
    with tempfile.TemporaryDirectory() as work:
        bag = Path(work) / 'arm'
        write_arm_bag(bag, config, move, ArmSynthOptions(duration_s=RECORD_S, noise_m=0.0))
        plot_arm_snapshots(
            bag,
            out,
            times=SNAPSHOTS_S,
            move_end_s=MOVE_S,
            title='config/arm_3link.yaml: a 1 s move, then the ring-down',
        )
    print(f'wrote {out}')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
