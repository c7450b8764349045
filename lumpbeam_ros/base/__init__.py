"""The ground floor: what every other floor stands on, and nothing of the domain.

- :mod:`~.errors`: the exceptions of a user's mistakes;
- :mod:`~.interface`: the graph's names (topics, types, frames, statuses), declared once;
- :mod:`~.schema`: declared settings (name, type, default, bounds, unit) and their checks;
- :mod:`~.paramfile`: ROS 2 parameter files read without ROS;
- :mod:`~.resources`: where the package's own files (``config/``, ``data/``) are found;
- :mod:`~.blas`, :mod:`~.closing`, :mod:`~.interrupts`, :mod:`~.progress`: process plumbing
  (single-threaded BLAS, objects that close, signal handling, a progress bar).
"""

__all__ = [
    'blas',
    'closing',
    'errors',
    'interface',
    'interrupts',
    'paramfile',
    'progress',
    'resources',
    'schema',
]
