"""Objects that hold something open (a bag, a domain claim, child processes) and close it.

Each of them is used as ``with Thing(...) as thing:`` and closes on the way out, whether the
block ended or raised: what a bag writer wrote is still worth keeping, a claimed domain must
be freed and child processes stopped either way.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from types import TracebackType
from typing import Self


class ClosedOnExit(ABC):
    """A context manager that is itself, and calls its :meth:`close` on exit.

    A subclass says how it closes; one that does not cannot be made (``TypeError``).
    """

    @abstractmethod
    def close(self) -> None:
        """Releases what the object holds; a second call does nothing."""

    def __enter__(self) -> Self:
        return self

    def __exit__(
        self,
        exc_type: type[BaseException] | None,
        exc: BaseException | None,
        traceback: TracebackType | None,
    ) -> None:
        self.close()
