"""Writes the example joint trajectories the docs use (``examples/*.csv``).

Usage: ``python tools/example_moves.py``. Each is a rest-to-rest minimum-jerk move
(``s = 10 u^3 - 15 u^4 + 6 u^5``), in the CSV of doc/interfaces.md ("Joint trajectory files"):

- ``two_joint_move.csv``: two joints, 0 to (0.5, -0.3) rad in 0.2 s, 201 samples (shaping);
- ``arm_3link_move.csv``: the three joints of ``config/arm_3link.yaml``, 0 to
  (0.3, -0.4, 0.2) rad in 1 s, 101 samples (the arm).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory, write_trajectory_csv

ROOT = Path(__file__).resolve().parents[1]

#: File name -> (end angles, rad; duration, s; samples).
MOVES = {
    'two_joint_move.csv': ((0.5, -0.3), 0.2, 201),
    'arm_3link_move.csv': ((0.3, -0.4, 0.2), 1.0, 101),
}


def minimum_jerk(end: tuple[float, ...], duration_s: float, samples: int) -> JointTrajectory:
    """A rest-to-rest minimum-jerk move from zero to ``end``."""
    t = np.linspace(0.0, duration_s, samples)
    u = t / duration_s
    s = 10 * u**3 - 15 * u**4 + 6 * u**5
    return JointTrajectory(t, np.outer(s, end))


def main() -> int:
    """Writes every example move."""
    for name, (end, duration_s, samples) in MOVES.items():
        path = ROOT / 'examples' / name
        path.parent.mkdir(exist_ok=True)
        write_trajectory_csv(path, minimum_jerk(end, duration_s, samples))
        print(f'wrote {path}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
