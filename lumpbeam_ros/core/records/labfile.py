"""One channel of a lab's measurement file, with its time.

A lab records with LabVIEW, a data logger or a script, and hands over a LabVIEW measurement
file (``.lvm``), a CSV file (or columns apart by spaces under a ``#`` line of names, as
``numpy.savetxt`` writes them), a NumPy file or a MATLAB file. :func:`read_lab_file` reads one
channel of any of them as a :class:`LabRecord`: its samples and their times in seconds.

Time comes from the file where it holds one (a time column, LabVIEW's ``X_Value`` column, or
its ``X0`` and ``Delta_X``), or from a rate the user gives. It must increase: a file whose
time goes back or stands still is refused, not sorted, since the samples' order is then
unknown. An empty cell is a gap (``NaN``, kept in place so that the time stays whole); a cell
that is not a number is an error naming its row and column.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lumpbeam_ros.base.errors import RecordError

#: The file kinds by suffix.
CSV_SUFFIXES = ('.csv', '.tsv', '.txt')
LVM_SUFFIXES = ('.lvm',)
NUMPY_SUFFIXES = ('.npy', '.npz')
MATLAB_SUFFIXES = ('.mat',)
SUFFIXES = CSV_SUFFIXES + LVM_SUFFIXES + NUMPY_SUFFIXES + MATLAB_SUFFIXES
#: The field separators a CSV file may use, most specific first.
CSV_SEPARATORS = ('\t', ';', ',')
_LVM_MAGIC = 'LabVIEW Measurement'
_LVM_END = '***End_of_Header***'


@dataclass(frozen=True)
class ChannelChoice:
    """Which channel of a file is the record, and where its time comes from.

    Attributes:
        column: The channel: a column name (CSV, LabVIEW), an array name (``.npz``, MATLAB) or
            a column index (a 2-D ``.npy``); ``None`` when the file holds one channel.
        time_column: The time column or array, s (CSV, NumPy, MATLAB).
        rate_hz: The sampling rate, Hz, when the file holds no time (overrides a LabVIEW
            file's own).
    """

    column: str | None = None
    time_column: str | None = None
    rate_hz: float | None = None


@dataclass(frozen=True)
class LabRecord:
    """One channel of a measurement file.

    Attributes:
        t: Sample times, s, finite and strictly increasing.
        values: The samples in the file's unit; ``NaN`` where the file has no value.
        name: The channel's name in the file.
        source: The file.
    """

    t: np.ndarray
    values: np.ndarray
    name: str
    source: Path

    @property
    def gaps(self) -> int:
        """Samples without a value."""
        return int(np.count_nonzero(~np.isfinite(self.values)))

    @property
    def rate_hz(self) -> float:
        """The median sampling rate, Hz."""
        return float(1.0 / np.median(np.diff(self.t)))


def read_lab_file(path: str | Path, choice: ChannelChoice | None = None) -> LabRecord:
    """Reads one channel of a CSV, LabVIEW, NumPy or MATLAB file.

    Args:
        path: The file; its suffix says its kind (:data:`SUFFIXES`).
        choice: The channel and its time (default: the file's only channel, its own time).

    Returns:
        The channel and its times.

    Raises:
        RecordError: An unknown or unreadable file, a missing or non-numeric column, no time
            and no rate, time that does not increase, fewer than 2 samples, no value at all.
    """
    source = Path(path)
    choice = choice or ChannelChoice()
    if choice.rate_hz is not None and not (math.isfinite(choice.rate_hz) and choice.rate_hz > 0):
        raise RecordError(
            f'{source}: the rate must be a positive number of Hz, got {choice.rate_hz!r}'
        )
    suffix = source.suffix.lower()
    if suffix not in SUFFIXES:
        raise RecordError(
            f'{source}: unknown kind of file {suffix or "(no suffix)"!r}; '
            f'lumpbeam reads {", ".join(SUFFIXES)}'
        )
    if not source.is_file():
        raise RecordError(f'{source}: no such file')
    if suffix in LVM_SUFFIXES:
        name, values, t = _read_lvm(source, choice)
    elif suffix in NUMPY_SUFFIXES:
        name, values, t = _read_numpy(source, choice)
    elif suffix in MATLAB_SUFFIXES:
        name, values, t = _read_matlab(source, choice)
    else:
        name, values, t = _read_csv(source, choice)
    return _record(source, name, values, t, choice.rate_hz)


def _record(
    source: Path, name: str, values: np.ndarray, t: np.ndarray | None, rate_hz: float | None
) -> LabRecord:
    """Checks the samples and their time, and makes the record."""
    values = np.asarray(values, dtype=np.float64).ravel()
    if values.size < 2:
        raise RecordError(f'{source}: {name!r} holds {values.size} sample(s); need at least 2')
    values = np.where(np.isfinite(values), values, np.nan)
    if np.isnan(values).all():
        raise RecordError(f'{source}: {name!r} holds no numeric value')
    if rate_hz is not None:
        t = np.arange(values.size) / rate_hz
    if t is None:
        raise RecordError(
            f'{source}: no time for {name!r}: give its time column (--time-column) or its '
            'rate (--rate HZ)'
        )
    t = np.asarray(t, dtype=np.float64).ravel()
    if t.size != values.size:
        raise RecordError(f'{source}: {t.size} times for {values.size} samples of {name!r}')
    bad = np.flatnonzero(~np.isfinite(t))
    if bad.size:
        raise RecordError(f'{source}: time is not a number at sample {bad[0]} of {name!r}')
    steps = np.diff(t)
    back = np.flatnonzero(steps <= 0.0)
    if back.size:
        i = int(back[0])
        raise RecordError(
            f'{source}: time does not increase at sample {i + 1} of {name!r} '
            f'({t[i + 1]!r} s after {t[i]!r} s)'
        )
    return LabRecord(t=t, values=values, name=name, source=source)


def _pick(source: Path, names: Sequence[str], wanted: str | None, what: str) -> int:
    """The index of a named column: exactly, else by a unique case-insensitive match."""
    if wanted is None:
        if len(names) == 1:
            return 0
        raise RecordError(
            f'{source}: {len(names)} {what}s ({", ".join(map(repr, names))}); '
            'choose one with --column'
        )
    if wanted in names:
        return list(names).index(wanted)
    folded = [i for i, n in enumerate(names) if n.casefold() == wanted.strip().casefold()]
    if len(folded) == 1:
        return folded[0]
    raise RecordError(
        f'{source}: no {what} {wanted!r}; it has {", ".join(map(repr, names)) or "none"}'
    )


def _number(cell: str, decimal_comma: bool) -> float:
    """A cell as a number; an empty cell is a gap (NaN). Raises ValueError otherwise."""
    text = cell.strip()
    if not text:
        return math.nan
    if decimal_comma:
        text = text.replace(',', '.')
    return float(text)


def _text(source: Path) -> str:
    try:
        return source.read_text(encoding='utf-8-sig')
    except UnicodeDecodeError:
        try:
            return source.read_text(encoding='latin-1')
        except OSError as exc:
            raise RecordError(f'{source}: cannot read: {exc.strerror or exc}') from None
    except OSError as exc:
        raise RecordError(f'{source}: cannot read: {exc.strerror or exc}') from None


# -- CSV ----------------------------------------------------------------------------------------


def _read_csv(source: Path, choice: ChannelChoice) -> tuple[str, np.ndarray, np.ndarray | None]:
    text = _text(source)
    if '\x00' in text:
        raise RecordError(f'{source}: not a text file')
    lines = text.splitlines()
    first = next((i for i, line in enumerate(lines) if line.strip()), None)
    if first is None:
        raise RecordError(f'{source}: empty file')
    header_line = lines[first]
    data_line = next((line for line in lines[first + 1 :] if line.strip()), '')
    if data_line and not any(sep in data_line for sep in CSV_SEPARATORS):
        # Columns apart by spaces, the names after a '#' (numpy.savetxt's layout).
        names_text = header_line.strip().lstrip('#')
        names = [n.strip() for n in names_text.split(',' if ',' in names_text else None)]
        rows = [names, *(line.split() for line in lines[first + 1 :])]
        separator = ' '
    else:
        separator = max(CSV_SEPARATORS, key=header_line.count)
        if header_line.count(separator) == 0:
            separator = ','
        rows = list(csv.reader(io.StringIO('\n'.join(lines[first:])), delimiter=separator))
        names = [n.strip() for n in rows[0]]
    if all(_is_number(n) for n in names if n):
        raise RecordError(
            f'{source}: the first row holds numbers, not column names; add a header row'
        )
    time_column = None
    if choice.time_column is not None:
        time_column = _pick(source, names, choice.time_column, 'column')
    if choice.column is None:
        # The one column besides the time is the record.
        others = [i for i in range(len(names)) if i != time_column]
        column = others[_pick(source, [names[i] for i in others], None, 'column')]
    else:
        column = _pick(source, names, choice.column, 'column')
    decimal_comma = separator not in (',', ' ')
    wanted = [column] if time_column is None else [column, time_column]
    numbered = [
        (f'line {number}', row)
        for number, row in enumerate(rows[1:], start=first + 2)
        if any(cell.strip() for cell in row)  # not a blank line
    ]
    labels = [f'column {names[i]!r}' for i in wanted]
    table = _table(source, numbered, wanted, labels, decimal_comma)
    t = None if time_column is None else table[:, 1]
    return names[column], table[:, 0], t


def _table(
    source: Path,
    rows: Sequence[tuple[str, Sequence[str]]],
    columns: Sequence[int],
    labels: Sequence[str],
    decimal_comma: bool,
) -> np.ndarray:
    """Columns of text rows as numbers, a missing or empty cell a gap (NaN).

    Args:
        source: The file (for the error).
        rows: Each row's place in the file (``'line 12'``) and its cells.
        columns: The cells to read, by index.
        labels: What each of them is (``"column 'acc'"``), for the error.
        decimal_comma: Whether a decimal comma is read too.

    Raises:
        RecordError: A cell that is not a number, with its row and column.
    """
    table = np.full((len(rows), len(columns)), np.nan)
    for r, (where, cells) in enumerate(rows):
        for k, column in enumerate(columns):
            cell = cells[column] if column < len(cells) else ''
            try:
                table[r, k] = _number(cell, decimal_comma)
            except ValueError:
                raise RecordError(
                    f'{source}: {where}, {labels[k]}: {cell.strip()!r} is not a number'
                ) from None
    return table


def _is_number(text: str) -> bool:
    try:
        float(text.replace(',', '.'))
    except ValueError:
        return False
    return True


# -- LabVIEW measurement files ------------------------------------------------------------------


def _read_lvm(source: Path, choice: ChannelChoice) -> tuple[str, np.ndarray, np.ndarray | None]:
    """A LabVIEW measurement file (text, one segment): the channel and its X values."""
    if choice.time_column is not None:
        raise RecordError(
            f'{source}: a LabVIEW file gives its own time (X_Value, or X0 and Delta_X); '
            '--time-column is for CSV, NumPy and MATLAB files'
        )
    lines = _text(source).splitlines()
    if not lines or not lines[0].startswith(_LVM_MAGIC):
        raise RecordError(f'{source}: not a LabVIEW measurement file (no {_LVM_MAGIC!r} line)')
    ends = [i for i, line in enumerate(lines) if line.startswith(_LVM_END)]
    if len(ends) < 2:
        raise RecordError(f'{source}: a LabVIEW file without its channel header')
    if len(ends) > 2:
        raise RecordError(
            f'{source}: {len(ends) - 1} segments; lumpbeam reads LabVIEW files of one segment '
            '(save one segment per file, or export CSV)'
        )
    file_header = _lvm_header(lines[1 : ends[0]])
    channel_header = _lvm_header(lines[ends[0] + 1 : ends[1]])
    separator = {'tab': '\t', 'comma': ','}.get(file_header.get('Separator', ['Tab'])[0].lower())
    if separator is None:
        raise RecordError(f'{source}: unknown separator {file_header["Separator"][0]!r}')
    decimal_comma = file_header.get('Decimal_Separator', ['.'])[0] == ','
    x_columns = file_header.get('X_Columns', ['One'])[0].lower()
    try:
        channels = int(channel_header.get('Channels', ['1'])[0])
    except ValueError:
        raise RecordError(f'{source}: Channels is not a number') from None
    body = [line for line in lines[ends[1] + 1 :] if line.strip()]
    names: list[str] = []
    if body and not _is_number(body[0].split(separator)[0]):
        names = [n.strip() for n in body[0].split(separator)]
        body = body[1:]
    layout = _lvm_layout(source, names, channels, x_columns)
    channel_names = [name for name, _ in layout]
    index = _pick(source, channel_names, choice.column, 'channel')
    value_column, x_column = layout[index][1]
    columns = [value_column] if x_column is None else [value_column, x_column]
    name = channel_names[index]
    numbered = [(f'data row {i + 1}', line.split(separator)) for i, line in enumerate(body)]
    labels = [f'channel {name!r}', f'X_Value of channel {name!r}']
    table = _table(source, numbered, columns, labels, decimal_comma)
    if x_column is not None:
        return name, table[:, 0], table[:, 1]
    x0 = _lvm_number(source, channel_header, 'X0', index, 0.0)
    dx = _lvm_number(source, channel_header, 'Delta_X', index, math.nan)
    if not (math.isfinite(dx) and dx > 0.0):
        return name, table[:, 0], None
    return name, table[:, 0], x0 + dx * np.arange(len(body))


def _lvm_header(lines: Sequence[str]) -> dict[str, list[str]]:
    """A header block's ``key<TAB>value...`` lines (LabVIEW separates them by tabs)."""
    header = {}
    for line in lines:
        key, *values = line.rstrip('\r').split('\t')
        if key.strip():
            header[key.strip()] = [v.strip() for v in values if v.strip()] or ['']
    return header


def _lvm_number(
    source: Path, header: dict[str, list[str]], key: str, index: int, default: float
) -> float:
    values = header.get(key)
    if not values:
        return default
    text = values[min(index, len(values) - 1)]
    try:
        return float(text.replace(',', '.'))
    except ValueError:
        raise RecordError(f'{source}: {key} {text!r} is not a number') from None


def _lvm_layout(
    source: Path, names: list[str], channels: int, x_columns: str
) -> list[tuple[str, tuple[int, int | None]]]:
    """Each channel's name and its (value column, X column or None)."""
    pairs: list[tuple[int, int | None]]
    if x_columns == 'multi':
        pairs = [(2 * i + 1, 2 * i) for i in range(channels)]
    elif x_columns == 'one':
        pairs = [(i + 1, 0) for i in range(channels)]
    elif x_columns == 'no':
        pairs = [(i, None) for i in range(channels)]
    else:
        raise RecordError(f'{source}: unknown X_Columns {x_columns!r}')
    layout = []
    for number, (value, x) in enumerate(pairs):
        name = names[value] if value < len(names) and names[value] else f'channel {number + 1}'
        layout.append((name, (value, x)))
    return layout


# -- NumPy and MATLAB ---------------------------------------------------------------------------


def _read_numpy(source: Path, choice: ChannelChoice) -> tuple[str, np.ndarray, np.ndarray | None]:
    try:
        loaded = np.load(source, allow_pickle=False)
    except (OSError, ValueError, EOFError) as exc:
        raise RecordError(f'{source}: not a NumPy file NumPy can read safely: {exc}') from None
    if isinstance(loaded, np.ndarray):
        return _from_array(source, loaded, choice)
    with loaded:
        arrays = {name: loaded[name] for name in loaded.files}
    return _from_named(source, arrays, choice, 'array')


def _from_array(
    source: Path, array: np.ndarray, choice: ChannelChoice
) -> tuple[str, np.ndarray, np.ndarray | None]:
    """A ``.npy`` array: 1-D, or 2-D with its channel (and time) chosen by column index."""
    array = _numeric(source, array, 'the array')
    if array.ndim == 1:
        if choice.column not in (None, '0'):
            raise RecordError(f'{source}: a 1-D array has no column {choice.column!r}')
        if choice.time_column is not None:
            raise RecordError(f'{source}: a 1-D array has no time column; give --rate')
        return 'column 0', array, None
    if array.ndim != 2:
        raise RecordError(f'{source}: a {array.ndim}-D array; need 1-D, or 2-D with --column')
    if choice.column is None:
        raise RecordError(
            f'{source}: a 2-D array of shape {array.shape}: choose its column with --column INDEX'
        )
    column = _index(source, choice.column, array.shape[1])
    t = None
    if choice.time_column is not None:
        t = array[:, _index(source, choice.time_column, array.shape[1])]
    return f'column {column}', array[:, column], t


def _index(source: Path, text: str, count: int) -> int:
    try:
        index = int(text)
    except ValueError:
        raise RecordError(f'{source}: column {text!r} is not an index (0..{count - 1})') from None
    if not 0 <= index < count:
        raise RecordError(f'{source}: column {index} is outside 0..{count - 1}')
    return index


def _numeric(source: Path, array: np.ndarray, what: str) -> np.ndarray:
    if not (np.issubdtype(array.dtype, np.number) or array.dtype == np.bool_):
        raise RecordError(f'{source}: {what} holds {array.dtype}, not numbers')
    if np.iscomplexobj(array):
        raise RecordError(f'{source}: {what} holds complex numbers')
    return np.asarray(array, dtype=np.float64)


def _from_named(
    source: Path, arrays: dict[str, np.ndarray], choice: ChannelChoice, what: str
) -> tuple[str, np.ndarray, np.ndarray | None]:
    """A named vector (``.npz`` array, MATLAB variable) and its named time, if any."""
    names = sorted(arrays)
    candidates = (
        names if choice.column is not None else [n for n in names if n != choice.time_column]
    )
    name = candidates[_pick(source, candidates, choice.column, what)]
    values = _vector(source, arrays[name], name)
    t = None
    if choice.time_column is not None:
        time_name = names[_pick(source, names, choice.time_column, what)]
        t = _vector(source, arrays[time_name], time_name)
    return name, values, t


def _vector(source: Path, array: np.ndarray, name: str) -> np.ndarray:
    array = _numeric(source, np.asarray(array), repr(name))
    squeezed = np.squeeze(array)
    if squeezed.ndim != 1:
        raise RecordError(f'{source}: {name!r} has shape {array.shape}, not a vector')
    return squeezed


def _read_matlab(source: Path, choice: ChannelChoice) -> tuple[str, np.ndarray, np.ndarray | None]:
    from scipy.io import loadmat
    from scipy.io.matlab import MatReadError

    try:
        loaded = loadmat(source)
    except NotImplementedError:
        raise RecordError(
            f'{source}: a MATLAB v7.3 (HDF5) file; save it with -v7, or export CSV'
        ) from None
    except (OSError, ValueError, TypeError, MatReadError) as exc:
        raise RecordError(f'{source}: not a MATLAB file: {exc}') from None
    arrays = {k: v for k, v in loaded.items() if not k.startswith('__')}
    return _from_named(source, arrays, choice, 'variable')
