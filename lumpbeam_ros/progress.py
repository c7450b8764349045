"""A one-line text progress bar for long jobs (reading a bag, running a campaign)."""

from __future__ import annotations

import sys
from typing import TextIO

#: A job with more units than this draws its bar even when the stream is not a TTY (a
#: bag of 200 000 poses takes long enough that a log wants to see it move).
LONG_JOB_UNITS = 200_000


class Progress:
    """A one-line progress bar on a stream, drawn only when it is a TTY or the job is long.

    Args:
        total: Units of work expected.
        label: What is being done.
        stream: Where to draw (default ``sys.stderr``).
        width: Characters of the bar.
        long_job: A job with more units than this draws even when the stream is not a TTY
            (``None``: only on a TTY; default :data:`LONG_JOB_UNITS`).
    """

    def __init__(
        self,
        total: int,
        label: str,
        stream: TextIO | None = None,
        width: int = 30,
        long_job: int | None = LONG_JOB_UNITS,
    ):
        self.stream = stream or sys.stderr
        self.total = max(int(total), 1)
        self.label = label
        self.width = width
        self.done = 0
        self._shown = -1
        self.enabled = self.stream.isatty() or (long_job is not None and total > long_job)

    def tick(self, units: int = 1, note: str = '') -> None:
        """Counts ``units`` of work; redraws at each whole per cent (or when ``note`` is given).

        Args:
            units: Work done since the last call.
            note: A short text drawn after the percentage (e.g. failures so far).
        """
        self.done += units
        percent = min(100, 100 * self.done // self.total)
        if self.enabled and (percent != self._shown or note):
            self._shown = percent
            filled = self.width * percent // 100
            bar = '#' * filled + '.' * (self.width - filled)
            tail = f' {note}' if note else ''
            self.stream.write(f'\r{self.label} [{bar}] {percent:3d}%{tail}')
            self.stream.flush()

    def close(self) -> None:
        """Ends the line."""
        if self.enabled and self._shown >= 0:
            self.stream.write('\n')
            self.stream.flush()
