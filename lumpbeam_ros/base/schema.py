"""Declared node parameters: name, type, default, range, unit, description, read-only.

One :class:`ParameterSchema` per node lists every parameter the node declares, as
generate_parameter_library's YAML does for C++ nodes (``type``, ``default_value``,
``description``, ``read_only``, ``validation: {bounds<>, gt<>, one_of<>, fixed_size<>}``).
From it the node adapter (:mod:`lumpbeam_ros.nodes.ros_parameters`) builds the
descriptors and the on-set check, and :mod:`lumpbeam_ros.nodes.params.reference`
writes ``doc/parameters.md``. The schema is plain Python: no ROS import, so the command line
and the tests use it as they are.

>>> spec = ParameterSpec('rate_hz', 'double', 180.0, 'output rate', 'Hz', Bounds(1.0, 2000.0))
>>> spec.problem(0.5)
'must be in [1, 2000], got 0.5'
>>> spec.problem(90) is None  # an integer is the double it names, as in YAML
True
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import Field, dataclass, field, fields
from pathlib import Path
from typing import Any, ClassVar, Literal, Protocol, TypeAlias, TypeVar, cast

from lumpbeam_ros.base.errors import ConfigError

#: The ROS parameter types a schema may declare.
ParameterKind: TypeAlias = Literal['bool', 'int', 'double', 'string', 'double[]']
#: A parameter's value, as rclpy gives it.
ParameterValue: TypeAlias = bool | int | float | str | tuple[float, ...] | list[float]


def _number(value: float) -> str:
    return f'{value:g}'


@dataclass(frozen=True)
class Bounds:
    """An interval a number must lie in (``None``: unbounded on that side).

    Attributes:
        low: The lower bound.
        high: The upper bound.
        low_open: The lower bound itself is excluded (``> low``, generate_parameter_library's
            ``gt<>``); otherwise included (``>= low``, ``gt_eq<>``).
        high_open: The upper bound itself is excluded (``< high``, ``lt<>``).
    """

    low: float | None = None
    high: float | None = None
    low_open: bool = False
    high_open: bool = False

    def __post_init__(self) -> None:
        if self.low is None and self.high is None:
            raise ValueError('bounds need a low or a high end')
        if self.low is not None and self.high is not None and self.low >= self.high:
            raise ValueError(f'empty bounds [{self.low}, {self.high}]')

    def contains(self, value: float) -> bool:
        """Whether ``value`` lies in the interval (NaN never does)."""
        if math.isnan(value):
            return False
        if self.low is not None and (value <= self.low if self.low_open else value < self.low):
            return False
        return not (
            self.high is not None and (value >= self.high if self.high_open else value > self.high)
        )

    def describe(self) -> str:
        """The interval in words: ``positive``, ``at least 64``, ``in [0, 1]``, ``in (0, 0.5)``."""
        if self.high is None and self.low == 0.0:
            return 'positive' if self.low_open else 'non-negative'
        return self._spelled(('above', 'at least'), ('below', 'at most'), 'in ')

    def notation(self) -> str:
        """The interval as a formula for tables: ``> 0``, ``>= 64``, ``[0, 1]``, ``(0, 0.5)``."""
        return self._spelled(('>', '>='), ('<', '<='), '')

    def _spelled(self, low: tuple[str, str], high: tuple[str, str], interval: str) -> str:
        """The interval in the words given (each pair: when open, when closed).

        Args:
            low: Before the number of a lower bound alone (``('above', 'at least')``).
            high: Before the number of an upper bound alone.
            interval: Before a bracketed pair of bounds (``'in '``).

        Returns:
            The interval spelled.
        """
        if self.high is None:
            return f'{low[0] if self.low_open else low[1]} {_number(self.low or 0.0)}'
        if self.low is None:
            return f'{high[0] if self.high_open else high[1]} {_number(self.high)}'
        left, right = '(' if self.low_open else '[', ')' if self.high_open else ']'
        return f'{interval}{left}{_number(self.low)}, {_number(self.high)}{right}'


@dataclass(frozen=True)
class ParameterSpec:
    """One declared parameter.

    Attributes:
        name: The dotted ROS name, e.g. ``window.length_s``.
        kind: Its ROS type.
        default: Its value when neither a params file nor ``-p`` gives one.
        description: One or two sentences (what ``ros2 param describe`` shows).
        unit: The unit of the value (empty: none).
        bounds: The interval a number (every element of a ``double[]``) must lie in.
        choices: The values a string may take (empty: any).
        length: The number of elements of a ``double[]``.
        read_only: Set at start only (``--params-file``, ``-p``), not while running.
    """

    name: str
    kind: ParameterKind
    default: ParameterValue
    description: str
    unit: str = ''
    bounds: Bounds | None = None
    choices: tuple[str, ...] = ()
    length: int | None = None
    read_only: bool = True

    def __post_init__(self) -> None:
        if self.bounds is not None and self.kind not in ('int', 'double', 'double[]'):
            raise ValueError(f'{self.name}: bounds on a {self.kind} parameter')
        if self.choices and self.kind != 'string':
            raise ValueError(f'{self.name}: choices on a {self.kind} parameter')
        if (self.length is not None) != (self.kind == 'double[]'):
            raise ValueError(f'{self.name}: a double[] parameter, and only one, has a length')
        problem = self.problem(self.default)
        if problem is not None:
            raise ValueError(f'{self.name}: default {self.default!r}: {problem}')

    def problem(self, value: object) -> str | None:
        """Checks a value against the type, range, choices and length.

        An integer is accepted for a ``double`` (YAML and ``-p`` write ``2400`` for
        ``2400.0``); doubles must be finite.

        Args:
            value: The value offered.

        Returns:
            ``None`` when it is acceptable, else what is wrong, e.g.
            ``'must be positive, got -1.0'``.
        """
        if self.kind == 'bool':
            return None if isinstance(value, bool) else f'must be true or false, got {value!r}'
        if self.kind == 'string':
            if not isinstance(value, str):
                return f'must be a string, got {value!r}'
            if self.choices and value not in self.choices:
                return f'must be one of {", ".join(self.choices)}, got {value!r}'
            return None
        if self.kind == 'double[]':
            return self._array_problem(value)
        return self._number_problem(value)

    def _number_problem(self, value: object) -> str | None:
        if isinstance(value, bool) or not isinstance(value, int | float):
            noun = 'an integer' if self.kind == 'int' else 'a number'
            return f'must be {noun}, got {value!r}'
        if self.kind == 'int' and not isinstance(value, int):
            return f'must be an integer, got {value!r}'
        if not math.isfinite(value):
            return f'must be finite, got {value!r}'
        if self.bounds is not None and not self.bounds.contains(float(value)):
            return f'must be {self.bounds.describe()}, got {value!r}'
        return None

    def _array_problem(self, value: object) -> str | None:
        expected = f'a list of {self.length} finite numbers'
        if not isinstance(value, Sequence) or isinstance(value, str):
            return f'must be {expected}, got {value!r}'
        items = list(value)
        if len(items) != self.length or any(
            isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v)
            for v in items
        ):
            return f'must be {expected}, got {value!r}'
        if self.bounds is not None and not all(self.bounds.contains(float(v)) for v in items):
            return f'every element must be {self.bounds.describe()}, got {value!r}'
        return None

    def constraints(self) -> str:
        """What a value must satisfy beyond its type, in short (empty: nothing)."""
        parts = []
        if self.length is not None:
            parts.append(f'{self.length} elements')
        if self.bounds is not None:
            parts.append(self.bounds.notation())
        if self.choices:
            parts.append(f'one of {", ".join(self.choices)}')
        return '; '.join(parts)


@dataclass(frozen=True)
class ParameterSchema:
    """Every parameter of one node.

    Attributes:
        node: The node's name, which is also its executable's (``camera_node``).
        summary: What the node does, one sentence (the reference's heading text).
        parameters: The parameters, in the order they are documented.
        config_file: The package's parameter file under ``config/`` whose values are the
            defaults (empty: none); a test holds the two equal.
        file_only: Parameters of ``config_file`` that the node does not declare, for the
            commands that read the file (documented with the node).
    """

    node: str
    summary: str
    parameters: tuple[ParameterSpec, ...]
    config_file: str = ''
    file_only: tuple[ParameterSpec, ...] = ()
    _by_name: dict[str, ParameterSpec] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        by_name = {spec.name: spec for spec in self.parameters}
        if len(by_name) != len(self.parameters):
            raise ValueError(f'{self.node}: a parameter is declared twice')
        object.__setattr__(self, '_by_name', by_name)

    def __iter__(self) -> Iterator[ParameterSpec]:
        """Iterates over the parameters in their documented order."""
        return iter(self.parameters)

    def __contains__(self, name: object) -> bool:
        """Whether the schema declares ``name``."""
        return name in self._by_name

    def __getitem__(self, name: str) -> ParameterSpec:
        """The parameter ``name``.

        Raises:
            KeyError: Not declared.
        """
        return self._by_name[name]

    @property
    def names(self) -> list[str]:
        """The parameter names in their documented order."""
        return [spec.name for spec in self.parameters]

    def defaults(self) -> dict[str, ParameterValue]:
        """Every parameter's default, by name."""
        return {spec.name: spec.default for spec in self.parameters}

    def problem(self, name: str, value: object) -> str | None:
        """Checks one value; the reason names the parameter.

        Args:
            name: The parameter.
            value: The value offered.

        Returns:
            ``None`` when acceptable, else e.g. ``'rate_hz: must be in [1, 2000], got 0.5'``
            (an undeclared name is a problem too).
        """
        if name not in self._by_name:
            return f'{name}: not a parameter of {self.node}'
        problem = self._by_name[name].problem(value)
        return None if problem is None else f'{name}: {problem}'

    def first_problem(self, values: Mapping[str, object]) -> str | None:
        """The first problem among ``values`` in documented order (see :meth:`problem`)."""
        for name in [*self.names, *sorted(set(values) - set(self._by_name))]:
            if name in values:
                problem = self.problem(name, values[name])
                if problem is not None:
                    return problem
        return None


# --- A configuration object whose fields are declared parameters ------------------------------

_T = TypeVar('_T', bound=ParameterValue)


class DeclaredFields(Protocol):
    """A dataclass whose fields are declared with :func:`setting` (others are no parameter)."""

    __dataclass_fields__: ClassVar[dict[str, Field[Any]]]


_S = TypeVar('_S', bound=DeclaredFields)


def _kind(default: object) -> ParameterKind:
    if isinstance(default, bool):
        return 'bool'
    if isinstance(default, int):
        return 'int'
    if isinstance(default, float):
        return 'double'
    if isinstance(default, str):
        return 'string'
    return 'double[]'


def setting(
    name: str,
    default: _T,
    description: str,
    unit: str = '',
    bounds: Bounds | None = None,
    choices: tuple[str, ...] = (),
) -> _T:
    """Declares a configuration field as a node parameter: the one place it is written.

    The field's type follows its default (``bool``, ``int``, ``float``, ``str`` or a tuple of
    floats, a ``double[]`` of that length). Used as a dataclass field's default::

        window_s: float = setting('window.length_s', 10.0, 'length of the window', 's', POSITIVE)

    Args:
        name: The dotted parameter name.
        default: The default value.
        description: One line (what ``ros2 param describe`` shows).
        unit: The unit (empty: none).
        bounds: The interval a number must lie in.
        choices: The values a string may take.

    Returns:
        The dataclass field (typed as its value, for the type checker).
    """
    kind = _kind(default)
    length = len(cast(tuple[float, ...], default)) if kind == 'double[]' else None
    spec = ParameterSpec(name, kind, default, description, unit, bounds, choices, length)
    return field(default=default, metadata={'parameter': spec})


def settings_specs(cls: type[DeclaredFields]) -> tuple[ParameterSpec, ...]:
    """The parameters a settings class declares, in field order."""
    return tuple(f.metadata['parameter'] for f in fields(cls) if 'parameter' in f.metadata)


def _typed(spec: ParameterSpec, value: object) -> object:
    if spec.kind == 'double':
        return float(cast(float, value))
    if spec.kind == 'double[]':
        return tuple(float(v) for v in cast(Sequence[float], value))
    return value


def settings_from_parameters(cls: type[_S], params: Mapping[str, Any], source: str | Path) -> _S:
    """Builds a settings object from flat (dotted) parameters, checked against its fields.

    A missing parameter takes its default. After each value is checked alone, a class that
    relates its values has its ``relation_problem()`` asked (``(key, what is wrong)`` or
    ``None``).

    Args:
        cls: The settings class.
        params: Flat parameters (a parameter file's, a node's); others are ignored.
        source: Where they came from, for error messages.

    Returns:
        The settings.

    Raises:
        ConfigError: A wrong type, a value out of range or a broken relation, naming the key.
    """
    values = {}
    for f in fields(cls):
        if 'parameter' not in f.metadata:
            continue  # not a parameter: its default stands
        spec: ParameterSpec = f.metadata['parameter']
        value = params.get(spec.name, spec.default)
        problem = spec.problem(value)
        if problem is not None:
            raise ConfigError(source, spec.name, problem)
        values[f.name] = _typed(spec, value)
    settings = cls(**values)
    relation = getattr(settings, 'relation_problem', None)
    broken = relation() if relation is not None else None
    if broken is not None:
        raise ConfigError(source, broken[0], broken[1])
    return settings


def settings_to_parameters(settings: DeclaredFields) -> dict[str, Any]:
    """The flat parameters that read back as ``settings``."""
    return {
        f.metadata['parameter'].name: getattr(settings, f.name)
        for f in fields(settings)
        if 'parameter' in f.metadata
    }
