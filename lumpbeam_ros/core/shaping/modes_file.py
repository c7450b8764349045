"""The modes to shape for, read from the JSON that ``lumpbeam analyze`` writes.

The file's ``modes`` list (``{natural_frequency_hz, damping_ratio, ...}`` per mode, ordered
by frequency) is taken whole; a file without it gives its one mode by the top-level keys
``natural_frequency_hz`` and ``damping_ratio``. A value written as null (no estimate) or out
of range is refused: a shaper is never built on an invalid estimate.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from lumpbeam_ros.base.errors import ConfigError, LumpbeamError
from lumpbeam_ros.core.shaping.impulses import Mode

FREQUENCY_KEY = 'natural_frequency_hz'
DAMPING_KEY = 'damping_ratio'


def read_modes_json(path: str | Path) -> list[Mode]:
    """Reads the modes of an identification result.

    Args:
        path: A JSON file of ``lumpbeam analyze``.

    Returns:
        The modes, at least one, in the file's order.

    Raises:
        ConfigError: The file is missing, unreadable or not JSON, has neither a ``modes``
            list nor the top-level keys, or a mode's frequency or damping ratio is missing,
            null, not a number or out of range.
    """
    path = Path(path)
    try:
        document = json.loads(path.read_text(encoding='utf-8'))
    except FileNotFoundError:
        raise ConfigError(path, '', 'no such file') from None
    except OSError as exc:
        raise ConfigError(path, '', f'cannot read it ({exc.strerror or exc})') from None
    except (UnicodeDecodeError, json.JSONDecodeError):
        raise ConfigError(path, '', 'not a JSON file') from None
    if not isinstance(document, Mapping):
        raise ConfigError(path, '', 'expected a JSON object (the output of lumpbeam analyze)')
    listed = document.get('modes')
    if listed is None:
        if FREQUENCY_KEY not in document:
            raise ConfigError(path, '', f'has neither a modes list nor {FREQUENCY_KEY}')
        return [_mode(path, '', document)]
    if not isinstance(listed, list) or not listed:
        raise ConfigError(path, 'modes', 'expected a non-empty list of modes')
    return [_mode(path, f'modes[{i}]', entry) for i, entry in enumerate(listed)]


def _mode(path: Path, where: str, entry: Any) -> Mode:
    if not isinstance(entry, Mapping):
        raise ConfigError(path, where, f'expected an object with {FREQUENCY_KEY}, {DAMPING_KEY}')
    values = []
    for key in (FREQUENCY_KEY, DAMPING_KEY):
        name = f'{where}.{key}' if where else key
        value = entry.get(key)
        if value is None:
            raise ConfigError(path, name, 'missing or null (no estimate)')
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise ConfigError(path, name, f'not a number: {value!r}')
        if not math.isfinite(value):
            raise ConfigError(path, name, f'not finite: {value!r}')
        values.append(float(value))
    try:
        return Mode(values[0], values[1])
    except LumpbeamError as exc:
        raise ConfigError(path, where or FREQUENCY_KEY, str(exc)) from None
