"""The live demo graph: child processes on a private ROS domain, and the demo's steps.

:mod:`~lumpbeam_ros.apps.demo.graph` starts, watches and stops the processes;
:mod:`~lumpbeam_ros.apps.demo.recording` reads what they recorded;
:mod:`~lumpbeam_ros.apps.demo.steps` lists the steps of ``lumpbeam demo``.
"""

__all__ = [
    'arm_loop',
    'graph',
    'live_diagnosis',
    'recording',
    'steps',
]
