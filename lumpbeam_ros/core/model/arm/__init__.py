"""The flexible arm: links of lumped segments on prescribed revolute joints, and their motion.

:mod:`~.joint_trajectory` is the joint motion commanded to an arm (and its CSV file);
:mod:`~.drive` what the servos make of it; :mod:`~.simulate` and :mod:`~.stream` the arm
moved along it, offline and as time passes.
"""

__all__ = [
    'config',
    'drive',
    'joint_trajectory',
    'ltv',
    'model',
    'residual',
    'simulate',
    'statics',
    'stream',
]
