"""Other work on the machine: busy loops beside a benchmark, one per core they take."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def busy_loops(count: int) -> Iterator[None]:
    """Runs ``count`` processes that spin on the CPU until the block ends.

    Args:
        count: How many (0 for none).

    Yields:
        Nothing; the loops run for the block.
    """
    loops = [subprocess.Popen([sys.executable, '-c', 'while True: pass']) for _ in range(count)]
    try:
        yield
    finally:
        for loop in loops:
            loop.kill()
            loop.wait()
