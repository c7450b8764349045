"""``lumpbeam demo``: the live graph as child processes on a private ROS domain, step by step.

:mod:`~lumpbeam_ros.apps.demo.run` holds a run's options and state;
:mod:`~lumpbeam_ros.apps.demo.steps` lists and orchestrates the steps;
:mod:`~lumpbeam_ros.apps.demo.graph` starts, watches and stops the processes;
:mod:`~lumpbeam_ros.apps.demo.accounting` counts what they published against what was
recorded; :mod:`~lumpbeam_ros.apps.demo.recording` reads the recording back;
:mod:`~lumpbeam_ros.apps.demo.summary` draws and tabulates the results;
:mod:`~lumpbeam_ros.apps.demo.arm_graph` is the arm demos' graph and driver;
:mod:`~lumpbeam_ros.apps.demo.arm_loop` is ``lumpbeam demo --arm``,
:mod:`~lumpbeam_ros.apps.demo.workspace_loop` ``lumpbeam demo --workspace``.
"""

__all__ = [
    'accounting',
    'arm_graph',
    'arm_loop',
    'graph',
    'live_diagnosis',
    'recording',
    'run',
    'steps',
    'summary',
    'workspace_loop',
]
