"""Machine-readable results: the ``--json`` files of the subcommands and the demo's summary."""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from lumpbeam_ros.base.errors import LumpbeamError


def plain_json(value: Any) -> Any:
    """Returns ``value`` with numpy arrays and scalars as lists and numbers, NaN and inf as None.

    Args:
        value: JSON-like data (dicts, lists, tuples, numbers, strings, numpy values).

    Returns:
        The same data, serializable by :func:`json.dumps` as strict JSON.
    """
    # numpy is imported here: the CLI imports this module before parsing, and `--help` must
    # stay light.
    import numpy as np

    if isinstance(value, dict):
        return {str(k): plain_json(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [plain_json(v) for v in value]
    if isinstance(value, np.ndarray):
        return [plain_json(v) for v in value.tolist()]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None  # JSON has no NaN or inf
    return value


def typed_values(values: Mapping[str, str]) -> dict[str, Any]:
    """A message's key-value strings (``DiagnosticStatus.values``) with numbers as numbers.

    Args:
        values: The strings by key.

    Returns:
        Each value as an ``int`` or a ``float`` when it reads as one (``nan`` as ``None``,
        as :func:`plain_json` writes it), else the string.
    """
    typed: dict[str, Any] = {}
    for key, text in values.items():
        try:
            typed[key] = int(text)
        except ValueError:
            try:
                typed[key] = float(text)
            except ValueError:
                typed[key] = text
    plain: dict[str, Any] = plain_json(typed)
    return plain


def write_json(path: str | Path, result: dict[str, Any]) -> None:
    """Writes a command's machine-readable result.

    Args:
        path: Output file; its folder is created when missing.
        result: JSON-serializable data; numpy values are converted, NaN and inf become null.

    Raises:
        LumpbeamError: The file cannot be written.
    """
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(json.dumps(plain_json(result), indent=2) + '\n', encoding='utf-8')
    except OSError as exc:
        raise LumpbeamError(f'cannot write JSON to {path}: {exc.strerror or exc}') from None
