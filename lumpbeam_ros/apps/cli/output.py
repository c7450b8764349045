"""Output shared by the subcommands: the ``--json`` file (written by the core), argument types."""

from __future__ import annotations

import argparse
import math

from lumpbeam_ros.apps.json_output import write_json

__all__ = ['non_negative_float', 'positive_float', 'positive_int', 'write_json']


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


def positive_int(text: str) -> int:
    """Argument type: a whole number, 1 or more.

    Args:
        text: The option's value.

    Returns:
        The number.

    Raises:
        argparse.ArgumentTypeError: Not a whole number, or below 1.
    """
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f'not a whole number: {text!r}') from None
    if value < 1:
        raise argparse.ArgumentTypeError(f'must be 1 or more, got {text!r}')
    return value
