"""ROS 2 parameter files, read without ROS.

The YAML files under ``config/`` are ordinary ROS 2 parameter files
(``<node or /**>: ros__parameters: {...}``), so the nodes take them with
``--ros-args --params-file`` and the core and the command line read the same files here.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml

from lumpbeam_ros.base.errors import ConfigError
from lumpbeam_ros.base.resources import config_path, packaged

#: libyaml's loader when PyYAML was built with it: the same safe subset of YAML, parsed ten
#: times faster than the pure-Python one (a command reads two or three files as it starts).
_SAFE_LOADER: Any = getattr(yaml, 'CSafeLoader', yaml.SafeLoader)


def safe_load(text: str) -> Any:
    """``yaml.safe_load`` with libyaml when available.

    Args:
        text: A YAML document.

    Returns:
        The parsed value.

    Raises:
        yaml.YAMLError: Not valid YAML.
    """
    return yaml.load(text, Loader=_SAFE_LOADER)


def flatten(tree: Mapping[str, Any], prefix: str = '') -> dict[str, Any]:
    """Flattens nested mappings into dotted keys, as ROS 2 names nested parameters.

    Args:
        tree: Nested mapping of parameter names to values.
        prefix: Prefix for every key (used in recursion).

    Returns:
        A flat dict, e.g. ``{'beam.length_m': 2.31}``.
    """
    flat: dict[str, Any] = {}
    for key, value in tree.items():
        name = f'{prefix}{key}'
        if isinstance(value, Mapping):
            flat.update(flatten(value, prefix=f'{name}.'))
        else:
            flat[name] = value
    return flat


def read_yaml_document(path: str | Path) -> Any:
    """Reads and parses a YAML file.

    Args:
        path: The file.

    Returns:
        The parsed document (any YAML value).

    Raises:
        ConfigError: The file is missing, unreadable or not YAML.
    """
    path = packaged(path)
    try:
        text = path.read_text(encoding='utf-8')
    except FileNotFoundError:
        raise ConfigError(path, '', 'no such file') from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(path, '', f'cannot read: {exc}') from None
    try:
        return safe_load(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, 'problem_mark', None)
        where = f' at line {mark.line + 1}' if mark is not None else ''
        raise ConfigError(path, '', f'not valid YAML{where}') from None


def read_parameter_file(path: str | Path) -> dict[str, Any]:
    """Reads the ``ros__parameters`` of every node section of a parameter file.

    Args:
        path: The YAML file.

    Returns:
        The parameters as a flat dict with dotted keys. Sections for several nodes are merged
        in file order.

    Raises:
        ConfigError: The file is missing, is not YAML, or is not a ROS 2 parameter file.
    """
    path = Path(path)
    document = read_yaml_document(path)
    if not isinstance(document, Mapping) or not document:
        raise ConfigError(path, '', 'expected a mapping of node names to ros__parameters')
    merged: dict[str, Any] = {}
    for node, section in document.items():
        if not isinstance(section, Mapping) or not isinstance(
            section.get('ros__parameters'), Mapping
        ):
            raise ConfigError(path, str(node), 'expected a ros__parameters mapping')
        merged.update(flatten(section['ros__parameters']))
    return merged


def parameter_file(path: str | Path | None, default: str) -> tuple[Path, dict[str, Any]]:
    """Reads a parameter file, or the package's own when none is given: the one loader.

    Args:
        path: The YAML file, or ``None``.
        default: The package's file used for ``None``, a name under ``config/``.

    Returns:
        The file read and its flat parameters (:func:`read_parameter_file`).

    Raises:
        ConfigError: The file is missing or malformed.
    """
    chosen = config_path(default) if path is None else Path(path)
    return chosen, read_parameter_file(chosen)


def check_known_keys(
    params: Mapping[str, Any], known: set[str] | frozenset[str], source: str | Path
) -> None:
    """Rejects any key that is not in ``known``, so a typo never passes silently.

    Args:
        params: Flat parameters.
        known: The accepted dotted keys.
        source: Where the parameters came from, for the message.

    Raises:
        ConfigError: For the first unknown key, in sorted order.
    """
    unknown = sorted(set(params) - set(known))
    if unknown:
        raise ConfigError(source, unknown[0], 'unknown key')


def _lookup(
    params: Mapping[str, Any], key: str, source: str | Path, default: Any
) -> tuple[Any, bool]:
    """The value of ``key`` and ``True``; ``(default, False)`` when it is absent.

    Raises:
        ConfigError: The key is absent and has no default (``None``).
    """
    if key in params:
        return params[key], True
    if default is None:
        raise ConfigError(source, key, 'missing')
    return default, False


def get_float(
    params: Mapping[str, Any],
    key: str,
    source: str | Path,
    default: float | None = None,
    *,
    positive: bool = False,
    non_negative: bool = False,
) -> float:
    """Reads a finite float, optionally requiring it to be positive or non-negative.

    Args:
        params: Flat parameters.
        key: Dotted key.
        source: Where the parameters came from, for the message.
        default: Used when the key is absent; ``None`` makes the key required.
        positive: Require ``value > 0``.
        non_negative: Require ``value >= 0``.

    Returns:
        The value as a float.

    Raises:
        ConfigError: The key is missing (and required), not a number, not finite or out of
            range.
    """
    value, given = _lookup(params, key, source, default)
    if not given:
        return float(value)
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ConfigError(source, key, f'must be a number, got {value!r}')
    value = float(value)
    if not math.isfinite(value):
        raise ConfigError(source, key, f'must be finite, got {value!r}')
    if positive and value <= 0.0:
        raise ConfigError(source, key, f'must be positive, got {value!r}')
    if non_negative and value < 0.0:
        raise ConfigError(source, key, f'must not be negative, got {value!r}')
    return value


def get_int(
    params: Mapping[str, Any],
    key: str,
    source: str | Path,
    default: int | None = None,
    *,
    minimum: int | None = None,
) -> int:
    """Reads an integer, optionally with a lower bound.

    Args:
        params: Flat parameters.
        key: Dotted key.
        source: Where the parameters came from, for the message.
        default: Used when the key is absent; ``None`` makes the key required.
        minimum: Smallest accepted value.

    Returns:
        The value.

    Raises:
        ConfigError: The key is missing (and required), not an integer, or below ``minimum``.
    """
    value, given = _lookup(params, key, source, default)
    if not given:
        return int(value)
    if isinstance(value, bool) or not isinstance(value, int):
        raise ConfigError(source, key, f'must be an integer, got {value!r}')
    if minimum is not None and value < minimum:
        raise ConfigError(source, key, f'must be at least {minimum}, got {value!r}')
    return value


def get_choice(
    params: Mapping[str, Any],
    key: str,
    source: str | Path,
    choices: tuple[str, ...],
    default: str | None = None,
) -> str:
    """Reads a string that must be one of ``choices``.

    Args:
        params: Flat parameters.
        key: Dotted key.
        source: Where the parameters came from, for the message.
        choices: The accepted values.
        default: Used when the key is absent; ``None`` makes the key required.

    Returns:
        The value.

    Raises:
        ConfigError: The key is missing (and required) or not one of ``choices``.
    """
    value, given = _lookup(params, key, source, default)
    if not given:
        return str(value)
    if value not in choices:
        raise ConfigError(source, key, f'must be one of {", ".join(choices)}; got {value!r}')
    return str(value)
