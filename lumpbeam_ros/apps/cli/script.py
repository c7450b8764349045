"""The ``lumpbeam`` console script (``setup.py``): signal handlers first, then the command.

:func:`~lumpbeam_ros.base.interrupts.run_script` installs the SIGINT and SIGTERM handlers before
anything but the standard library is imported, so a signal while the command's modules load
ends it as one during its work does: ``lumpbeam: interrupted`` and exit code 128 + the signal.
"""

from __future__ import annotations

import sys
from collections.abc import Callable

from lumpbeam_ros.base.interrupts import run_script


def lumpbeam() -> int:
    """Runs ``lumpbeam`` (:func:`lumpbeam_ros.apps.cli.main.main`)."""

    def load() -> Callable[[], int]:
        from lumpbeam_ros.apps.cli.main import main

        return main

    return run_script(load, _interrupted)


def _interrupted(signum: int) -> int:
    print('lumpbeam: interrupted', file=sys.stderr)
    return 128 + signum
