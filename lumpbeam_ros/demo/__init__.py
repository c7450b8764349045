"""The live demo graph: child processes on a private ROS domain, and the demo's steps.

:mod:`~lumpbeam_ros.demo.graph` starts, watches and stops the processes;
:mod:`~lumpbeam_ros.demo.recording` reads what they recorded;
:mod:`~lumpbeam_ros.demo.steps` lists the steps of ``lumpbeam demo``.
"""
