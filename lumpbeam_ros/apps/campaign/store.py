"""The campaign's results table: Parquet (the record a rerun resumes from) and CSV.

Both files are rewritten whole, each through a temporary file and ``os.replace``, so a
reader (or a crash) never sees half a file: the table on disk always holds every row
completed up to the last flush. A results file written by another version of the table
(:data:`~lumpbeam_ros.apps.campaign.task.SCHEMA_VERSION`) is refused, never overwritten.
"""

from __future__ import annotations

import os
import time
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from lumpbeam_ros.apps.campaign.task import ID_COLUMNS, SCHEMA_VERSION, Row
from lumpbeam_ros.base.errors import LumpbeamError

PARQUET = 'results.parquet'
CSV = 'results.csv'
#: Parquet schema metadata key holding the table's version.
VERSION_KEY = b'lumpbeam.campaign.schema_version'


class ResultsStore:
    """The rows of a campaign, kept in memory and flushed to ``OUT/results.{parquet,csv}``.

    Args:
        folder: The results folder (created when missing).
        flush_interval_s: A :meth:`add` flushes when the last flush is older than this.

    Raises:
        LumpbeamError: The folder cannot be created, or its ``results.parquet`` is
            unreadable or from another version of the table.
    """

    def __init__(self, folder: str | Path, flush_interval_s: float = 1.0):
        self.folder = Path(folder)
        self.flush_interval_s = flush_interval_s
        if self.folder.exists() and not self.folder.is_dir():
            raise LumpbeamError(f'--out {self.folder}: exists and is not a folder')
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise LumpbeamError(f'--out {self.folder}: {exc.strerror or exc}') from None
        self.rows: dict[str, Row] = {row['path']: row for row in self._load()}
        self._flushed = time.monotonic()
        self._dirty = False

    @property
    def parquet_path(self) -> Path:
        """The Parquet file."""
        return self.folder / PARQUET

    @property
    def csv_path(self) -> Path:
        """The CSV file."""
        return self.folder / CSV

    def _load(self) -> list[Row]:
        import pyarrow as pa
        import pyarrow.parquet as pq

        path = self.parquet_path
        if not path.exists():
            return []
        try:
            table = pq.read_table(path)
        except (OSError, pa.ArrowException) as exc:
            first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
            raise LumpbeamError(
                f'{path}: unreadable results file ({first}); move it away to start afresh'
            ) from None
        found = (table.schema.metadata or {}).get(VERSION_KEY, b'none').decode()
        if found != str(SCHEMA_VERSION):
            raise LumpbeamError(
                f'{path}: written by campaign table version {found}, this is version '
                f'{SCHEMA_VERSION}; move it away (or choose another --out) to start afresh'
            )
        rows: list[dict[str, Any]] = table.to_pylist()
        return rows

    def is_done(self, path: str, key: str) -> bool:
        """Whether a bag has a row with the same key (path, content, settings) and no error."""
        row = self.rows.get(path)
        return row is not None and row.get('key') == key and not row.get('error')

    def add(self, row: Row) -> None:
        """Adds (or replaces) a bag's row; flushes when the last flush is old enough."""
        self.rows[row['path']] = row
        self._dirty = True
        if time.monotonic() - self._flushed >= self.flush_interval_s:
            self.flush()

    def columns(self) -> list[str]:
        """Every column of the rows: the identity columns first, then in order of appearance."""
        names = dict.fromkeys(ID_COLUMNS)
        for row in self.rows.values():
            names.update(dict.fromkeys(row))
        return list(names)

    def flush(self) -> None:
        """Writes both files atomically.

        Raises:
            LumpbeamError: A file cannot be written.
        """
        import pyarrow as pa
        import pyarrow.csv as pacsv
        import pyarrow.parquet as pq

        columns = self.columns()
        rows = sorted(self.rows.values(), key=lambda r: r['path'])
        table = pa.Table.from_pylist(
            [{c: row.get(c) for c in columns} for row in rows],
        )
        table = table.replace_schema_metadata({VERSION_KEY: str(SCHEMA_VERSION).encode()})
        try:
            _replace(self.parquet_path, lambda tmp: pq.write_table(table, tmp))
            _replace(self.csv_path, lambda tmp: pacsv.write_csv(table, tmp))
        except (OSError, pa.ArrowException) as exc:
            raise LumpbeamError(f'cannot write results to {self.folder}: {exc}') from None
        self._flushed = time.monotonic()
        self._dirty = False

    def flush_if_dirty(self) -> None:
        """Flushes when rows were added since the last flush."""
        if self._dirty:
            self.flush()

    def completed(self) -> Iterable[Row]:
        """The rows, in path order."""
        return [self.rows[p] for p in sorted(self.rows)]


def _replace(path: Path, write: object) -> None:
    tmp = path.with_name(f'.{path.name}.{os.getpid()}.tmp')
    try:
        write(tmp)  # type: ignore[operator]
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)
