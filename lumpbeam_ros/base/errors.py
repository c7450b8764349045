"""Exceptions for mistakes in a user's input.

Every error a user can cause (a bad file, option or message) is a :class:`LumpbeamError`.
The command line prints its message as one line and exits with code 2; nodes log it as a
warning. Anything else that escapes is a bug.
"""

from __future__ import annotations

from pathlib import Path


class LumpbeamError(Exception):
    """A problem with a user's input, described in one line."""


class ConfigError(LumpbeamError):
    """A configuration file or parameter is missing, malformed or out of range.

    Args:
        source: The file (or other origin) the value came from.
        key: The offending key, dotted for nested keys; empty when the whole file is bad.
        problem: What is wrong, e.g. ``'must be positive, got -1.0'``.
    """

    def __init__(self, source: str | Path, key: str, problem: str):
        self.source = str(source)
        self.key = key
        self.problem = problem
        where = f'{self.source}: {key}' if key else self.source
        super().__init__(f'{where}: {problem}')


class BagError(LumpbeamError):
    """A bag is missing, unreadable, truncated or lacks a required topic."""


class RecordError(LumpbeamError):
    """A lab file cannot be read as a record: its format, a column, its time or its rate."""


class SolverBudgetError(LumpbeamError):
    """An integration spent its budget of work before reaching its end time.

    The beam's parameters make its equations too stiff or unstable to simulate (a strongly
    softening spring, say): the reference integrator's steps shrink without end.
    """
