"""A one-line text progress bar for long jobs (reading a bag, tracking footage, a campaign)."""

from __future__ import annotations

import sys
from typing import TextIO

#: A job with more units than this draws its bar even when the stream is not a TTY (a
#: bag of 200 000 poses takes long enough that a log wants to see it move).
LONG_JOB_UNITS = 200_000


class Progress:
    """A one-line progress bar on a stream, drawn only where someone watches it.

    Args:
        total: Units of work expected.
        label: What is being done.
        stream: Where to draw (default ``sys.stderr``).
        width: Characters of the bar.
        enabled: Whether to draw; ``None`` draws when the stream is a terminal, or when
            ``total`` exceeds ``long_job``.
        long_job: A total above which the bar is drawn even off a terminal (a log then
            shows that a long job is alive); ``None``: only on a terminal.
    """

    def __init__(
        self,
        total: int,
        label: str,
        stream: TextIO | None = None,
        width: int = 30,
        enabled: bool | None = None,
        long_job: int | None = LONG_JOB_UNITS,
    ):
        self.stream = stream or sys.stderr
        self.total = max(int(total), 1)
        self.label = label
        self.width = width
        self.done = 0
        self._shown = -1
        if enabled is None:
            enabled = self.stream.isatty() or (long_job is not None and total > long_job)
        self.enabled = bool(enabled)

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
