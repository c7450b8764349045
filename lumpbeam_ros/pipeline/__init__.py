"""The live demo graph: child processes on a private ROS domain, and the demo's steps.

:mod:`~lumpbeam_ros.pipeline.graph` starts, watches and stops the processes;
:mod:`~lumpbeam_ros.pipeline.analysis` reads what they recorded;
:mod:`~lumpbeam_ros.pipeline.demo` lists the steps of ``lumpbeam demo``.
"""
