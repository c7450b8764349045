"""lumpbeam_ros: live tip tracking, identification and vibration control of flexible links.

The package is four floors; each imports only the floors below it (``test/test_layers.py``):

- :mod:`~lumpbeam_ros.base`: the ground floor. Errors, the graph's names, the settings
  schema, parameter files and the package's own files; no numerics, no ROS.
- :mod:`~lumpbeam_ros.core`: the domain, ROS-free. The lumped model and the arm, bags,
  identification, vision, shaping, diagnosis, comparison.
- :mod:`~lumpbeam_ros.nodes`: the ROS 2 adapters. The nodes, their parameter schemas,
  real-time scheduling, private domains, the Foxglove server.
- :mod:`~lumpbeam_ros.apps`: what a user runs. The ``lumpbeam`` command line, the demo,
  campaigns, reports and their figures.
"""

__version__ = '0.1.0'

__all__ = [
    'base',
    'core',
    'nodes',
    'apps',
]
