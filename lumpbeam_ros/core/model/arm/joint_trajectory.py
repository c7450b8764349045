"""A joint trajectory: commanded joint angles against time, and its CSV file.

The file has the header ``time_s,joint_1,...,joint_n`` and one row per sample: time in
seconds, strictly increasing, and each joint's angle in rad. Between rows the angles are
interpolated linearly; before the first row the first row holds, after the last the last.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from lumpbeam_ros.base.errors import ConfigError, LumpbeamError
from lumpbeam_ros.base.resources import packaged

#: Name of the time column, the first of a trajectory file.
TIME_COLUMN = 'time_s'


def default_joint_names(count: int) -> tuple[str, ...]:
    """The joint names ``joint_1`` ... ``joint_<count>``, those of the file's header."""
    return tuple(f'joint_{i}' for i in range(1, count + 1))


@dataclass(frozen=True, eq=False)
class JointTrajectory:
    """Joint angles at strictly increasing times (read-only arrays).

    Attributes:
        time_s: Sample times (n,), s, strictly increasing, n >= 2.
        angles_rad: Joint angles (n, joints), rad, finite.
        joint_names: One name per joint; empty means ``joint_1`` ... ``joint_n``.

    Raises:
        LumpbeamError: Shapes that do not match, fewer than 2 samples, no joint, a value that
            is not finite, times that do not increase, or joint names that are not one
            distinct name per joint.
    """

    time_s: NDArray[np.float64]
    angles_rad: NDArray[np.float64]
    joint_names: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        time = np.array(self.time_s, dtype=float)
        angles = np.array(self.angles_rad, dtype=float)
        if angles.ndim == 1:
            angles = angles[:, np.newaxis]
        if time.ndim != 1 or angles.ndim != 2 or angles.shape[0] != time.size:
            raise LumpbeamError(
                f'joint trajectory: {time.size} times for angles of shape {angles.shape}'
            )
        if time.size < 2:
            raise LumpbeamError(f'joint trajectory: needs at least 2 samples, got {time.size}')
        if angles.shape[1] == 0:
            raise LumpbeamError('joint trajectory: no joint')
        if not (np.all(np.isfinite(time)) and np.all(np.isfinite(angles))):
            raise LumpbeamError('joint trajectory: times and angles must be finite numbers')
        steps = np.diff(time)
        if np.any(steps <= 0.0):
            i = int(np.argmax(steps <= 0.0)) + 1
            raise LumpbeamError(
                f'joint trajectory: times must increase, sample {i} is at {float(time[i])!r} s '
                f'after {float(time[i - 1])!r} s'
            )
        names = tuple(self.joint_names) or default_joint_names(angles.shape[1])
        if len(names) != angles.shape[1] or len(set(names)) != len(names) or '' in names:
            raise LumpbeamError(
                f'joint trajectory: {angles.shape[1]} joints need as many distinct names, '
                f'got {list(names)}'
            )
        time.setflags(write=False)
        angles.setflags(write=False)
        object.__setattr__(self, 'time_s', time)
        object.__setattr__(self, 'angles_rad', angles)
        object.__setattr__(self, 'joint_names', names)

    @property
    def joint_count(self) -> int:
        """Number of joints."""
        return int(self.angles_rad.shape[1])

    @property
    def duration_s(self) -> float:
        """Time from the first sample to the last, s."""
        return float(self.time_s[-1] - self.time_s[0])

    def at(self, t: ArrayLike) -> NDArray[np.float64]:
        """The joint angles at time(s) ``t``: linear between samples, held outside them.

        Args:
            t: A time in s, or an array of times.

        Returns:
            Angles (joints,) for a scalar time, else (``t.shape`` + (joints,)), rad.
        """
        times = np.asarray(t, dtype=float)
        columns = [np.interp(times, self.time_s, joint) for joint in self.angles_rad.T]
        return np.stack(columns, axis=-1)


def read_trajectory_csv(path: str | Path) -> JointTrajectory:
    """Reads a joint trajectory file (header ``time_s,joint_1,...,joint_n``).

    Args:
        path: The CSV file.

    Returns:
        The trajectory, with the joints named ``joint_1`` ... ``joint_n``.

    Raises:
        ConfigError: The file is missing or unreadable, its header is not ``time_s`` followed
            by ``joint_1`` ... ``joint_n``, a row has another number of values, a value is
            not a finite number, the times do not increase, or it has fewer than 2 rows.
    """
    path = packaged(path)
    try:
        with path.open(encoding='utf-8', newline='') as file:
            rows = [(n, row) for n, row in enumerate(csv.reader(file), start=1) if row]
    except FileNotFoundError:
        raise ConfigError(path, '', 'no such file') from None
    except UnicodeDecodeError:
        raise ConfigError(path, '', 'not a text file') from None
    except (OSError, csv.Error) as exc:
        problem = getattr(exc, 'strerror', None) or exc
        raise ConfigError(path, '', f'cannot read it ({problem})') from None
    if not rows:
        raise ConfigError(path, '', 'empty, expected the header time_s,joint_1,...,joint_n')
    header = [name.strip() for name in rows[0][1]]
    expected = [TIME_COLUMN, *default_joint_names(len(header) - 1)]
    if len(header) < 2 or header != expected:
        shown = ','.join(expected) if len(header) >= 2 else 'time_s,joint_1,...,joint_n'
        raise ConfigError(path, 'header', f'expected {shown}, got {",".join(header)}')
    values = np.empty((len(rows) - 1, len(header)))
    for i, (line, row) in enumerate(rows[1:]):
        if len(row) != len(header):
            raise ConfigError(
                path, f'line {line}', f'{len(row)} values for the {len(header)} columns'
            )
        for j, text in enumerate(row):
            values[i, j] = _number(path, line, header[j], text)
        if i > 0 and values[i, 0] <= values[i - 1, 0]:
            raise ConfigError(
                path,
                f'line {line}',
                f'time_s must increase, {float(values[i, 0])!r} after {float(values[i - 1, 0])!r}',
            )
    if values.shape[0] < 2:
        raise ConfigError(path, '', f'needs at least 2 rows, got {values.shape[0]}')
    return JointTrajectory(values[:, 0], values[:, 1:])


def _number(path: Path, line: int, column: str, text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise ConfigError(path, f'line {line}', f'{column} is not a number: {text!r}') from None
    if not math.isfinite(value):
        raise ConfigError(path, f'line {line}', f'{column} is not finite: {text.strip()}')
    return value


def write_trajectory_csv(path: str | Path, trajectory: JointTrajectory) -> None:
    """Writes a trajectory file that :func:`read_trajectory_csv` reads back exactly.

    The header names the joints ``joint_1`` ... ``joint_n`` in the trajectory's order, as the
    file format requires, whatever the trajectory's own joint names.

    Args:
        path: The CSV file to write (replaced if it exists).
        trajectory: The trajectory.

    Raises:
        LumpbeamError: The file cannot be written.
    """
    path = Path(path)
    header = [TIME_COLUMN, *default_joint_names(trajectory.joint_count)]
    table = np.column_stack([trajectory.time_s, trajectory.angles_rad])
    try:
        with path.open('w', encoding='utf-8', newline='') as file:
            writer = csv.writer(file, lineterminator='\n')
            writer.writerow(header)
            writer.writerows([repr(float(v)) for v in row] for row in table)
    except OSError as exc:
        raise LumpbeamError(f'cannot write {path}: {exc.strerror or exc}') from None
