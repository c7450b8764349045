"""Output shared by the subcommands: the ``--json`` file and argument types."""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import Any

from lumpbeam_ros.errors import LumpbeamError


def _plain(value: Any) -> Any:
    # numpy is imported here: the argument types below serve `--help`, which must stay light.
    import numpy as np

    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return [_plain(v) for v in value.tolist()]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None  # JSON has no NaN or inf
    return value


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
        path.write_text(json.dumps(_plain(result), indent=2) + '\n', encoding='utf-8')
    except OSError as exc:
        raise LumpbeamError(f'cannot write JSON to {path}: {exc.strerror or exc}') from None


def _bounded_float(text: str, allow_zero: bool) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f'not a number: {text!r}') from None
    if not math.isfinite(value) or value < 0.0 or (value == 0.0 and not allow_zero):
        kind = 'zero or positive' if allow_zero else 'a positive number'
        raise argparse.ArgumentTypeError(f'must be {kind}, got {text!r}')
    return value


def positive_float(text: str) -> float:
    """Argument type: a finite number greater than zero.

    Args:
        text: The option's value.

    Returns:
        The number.

    Raises:
        argparse.ArgumentTypeError: Not a positive finite number.
    """
    return _bounded_float(text, allow_zero=False)


def non_negative_float(text: str) -> float:
    """Argument type: a finite number greater than or equal to zero.

    Args:
        text: The option's value.

    Returns:
        The number.

    Raises:
        argparse.ArgumentTypeError: Not a non-negative finite number.
    """
    return _bounded_float(text, allow_zero=True)
