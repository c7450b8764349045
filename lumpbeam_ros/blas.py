"""Single-threaded BLAS for the small matrices of the identifier and the simulator.

The identifier works on matrices of a few dozen columns. A multi-threaded BLAS hands each
call to several threads, and on a busy two-core machine (a camera pipeline beside the
identifier) the hand-off alone costs tens of milliseconds; one thread is 20-30x faster here.
"""

from __future__ import annotations

from contextlib import AbstractContextManager
from typing import Any

import numpy  # noqa: F401  (loaded first, so the controller sees its BLAS)
import scipy.linalg  # noqa: F401  (scipy may bring its own BLAS)
from threadpoolctl import ThreadpoolController

_controller: ThreadpoolController | None = None


def single_threaded_blas() -> AbstractContextManager[Any]:
    """Returns a context in which every loaded BLAS uses one thread."""
    global _controller
    if _controller is None:
        _controller = ThreadpoolController()
    limit: AbstractContextManager[Any] = _controller.limit(limits=1, user_api='blas')
    return limit
