"""The ``lumpbeam`` command line: declared arguments, and one module per subcommand.

:mod:`~lumpbeam_ros.apps.cli.arguments` declares every subcommand's arguments with the standard
library alone; :mod:`~lumpbeam_ros.apps.cli.main` imports the module that runs a subcommand only
once it is chosen.
"""

__all__ = [
    'analyze',
    'arguments',
    'bench',
    'campaign',
    'compare',
    'demo',
    'dependencies',
    'diagnose',
    'doctor',
    'fit_links',
    'import_',
    'launch',
    'main',
    'modes',
    'output',
    'play',
    'record',
    'repair',
    'reproduce',
    'script',
    'shape',
    'synth',
    'track',
    'view',
]
