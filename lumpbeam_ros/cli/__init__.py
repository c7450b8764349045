"""The ``lumpbeam`` command line: declared arguments, and one module per subcommand.

:mod:`~lumpbeam_ros.cli.arguments` declares every subcommand's arguments with the standard
library alone; :mod:`~lumpbeam_ros.cli.main` imports the module that runs a subcommand only
once it is chosen.
"""
