"""Single-threaded BLAS for the small matrices of the identifier and the simulator.

The identifier works on matrices of a few dozen columns. A multi-threaded BLAS hands each
call to several threads, and on a busy two-core machine (a camera pipeline beside the
identifier) the hand-off alone costs tens of milliseconds; one thread is 20-30x faster here.
"""

from __future__ import annotations

import sys
from contextlib import AbstractContextManager
from typing import Any

import numpy  # noqa: F401  (loaded first, so the controller sees its BLAS)
from threadpoolctl import ThreadpoolController

_controller: ThreadpoolController | None = None
#: How many modules were loaded when the controller was built.
_modules_seen = 0


def single_threaded_blas() -> AbstractContextManager[Any]:
    """Returns a context in which every loaded BLAS uses one thread."""
    global _controller, _modules_seen
    # The controller only knows the libraries loaded when it was built. scipy brings a BLAS
    # of its own, but importing scipy here would cost ``lumpbeam analyze`` a third of a
    # second for a library it never calls; so the controller is rebuilt whenever a module
    # has been imported since (scipy.linalg, say), which a long run does only a few times.
    if _controller is None or len(sys.modules) != _modules_seen:
        _controller = ThreadpoolController()
        _modules_seen = len(sys.modules)
    limit: AbstractContextManager[Any] = _controller.limit(limits=1, user_api='blas')
    return limit
