"""Declares a node's parameters from its schema (:mod:`lumpbeam_ros.base.schema`).

The rclpy side of the one parameter mechanism, as generate_parameter_library's generated
``ParamListener`` is for C++ nodes: every parameter is declared with a ``ParameterDescriptor``
carrying its type, description, unit, read-only flag, range (``FloatingPointRange`` /
``IntegerRange``) and the rest of its constraints in ``additional_constraints``; values come
from ``--ros-args --params-file`` and ``-p`` as usual; one on-set callback refuses a value
the schema refuses, with the reason (``ros2 param set`` prints it), and keeps the old value.
A node calls it once, in ``__init__``::

    values = declare_parameters(self, SIMULATOR_SCHEMA, on_change=self._on_change)
"""

from __future__ import annotations

import math
import time
from collections import Counter
from collections.abc import Callable, Mapping, Sequence
from typing import Any, TypedDict, Unpack

from rcl_interfaces.msg import (
    FloatingPointRange,
    IntegerRange,
    ParameterDescriptor,
    ParameterType,
    SetParametersResult,
)
from rclpy.context import Context
from rclpy.exceptions import ParameterException
from rclpy.node import Node
from rclpy.parameter import Parameter

from lumpbeam_ros.base.errors import ConfigError
from lumpbeam_ros.base.schema import ParameterSchema, ParameterSpec
from lumpbeam_ros.nodes.realtime import REALTIME_PRIORITY, set_realtime_priority

#: Checks (and may apply) changes the schema accepted: ``None``, or why they are refused.
ChangeHook = Callable[[Mapping[str, Any]], str | None]


class NodeOptions(TypedDict, total=False):
    """How a node of the package is made, every one alike (all optional, by keyword).

    Attributes:
        context: The rclpy context (default: the global one).
        parameter_overrides: Values by name (``{'publish_rate_hz': 5.0}``), or ``Parameter``
            objects, on top of any ``--params-file`` (as ``-p`` would give them).
        namespace: The node's namespace (``'/beam_a'``); its topics resolve in it.
        cli_args: Node-specific ``--ros-args`` (e.g. ``--params-file``, ``-r``).
    """

    context: Context | None
    parameter_overrides: Mapping[str, Any] | Sequence[Parameter] | None
    namespace: str
    cli_args: Sequence[str] | None


_TYPES = {
    'bool': ParameterType.PARAMETER_BOOL,
    'int': ParameterType.PARAMETER_INTEGER,
    'double': ParameterType.PARAMETER_DOUBLE,
    'string': ParameterType.PARAMETER_STRING,
    'double[]': ParameterType.PARAMETER_DOUBLE_ARRAY,
}
_INT64 = 2**63 - 1

#: Parameters rclpy declares itself (``qos_overrides.*``: ``QoSOverridingOptions``).
RCLPY_PARAMETERS = frozenset({'use_sim_time', 'start_type_description_service'})
RCLPY_PREFIXES = ('qos_overrides.',)


def describe(spec: ParameterSpec) -> ParameterDescriptor:
    """The descriptor ``ros2 param describe`` shows and rclpy enforces for ``spec``.

    An open bound (``> 0``) is given as its closed interval; the on-set check refuses the
    bound itself.

    Args:
        spec: The parameter.

    Returns:
        The descriptor, statically typed.
    """
    unit = f' [{spec.unit}]' if spec.unit else ''
    descriptor = ParameterDescriptor(
        name=spec.name,
        type=_TYPES[spec.kind],
        description=f'{spec.description}{unit}',
        read_only=spec.read_only,
        additional_constraints=spec.constraints(),
    )
    bounds = spec.bounds
    if bounds is not None and spec.kind == 'double':
        low = -math.inf if bounds.low is None else float(bounds.low)
        high = math.inf if bounds.high is None else float(bounds.high)
        descriptor.floating_point_range = [FloatingPointRange(from_value=low, to_value=high)]
    elif bounds is not None and spec.kind == 'int':
        low_int = -_INT64 if bounds.low is None else math.ceil(bounds.low)
        high_int = _INT64 if bounds.high is None else math.floor(bounds.high)
        descriptor.integer_range = [IntegerRange(from_value=low_int, to_value=high_int)]
    return descriptor


def _as_declared(spec: ParameterSpec, value: Any) -> Any:
    if spec.kind == 'double':
        return float(value)
    if spec.kind == 'double[]':
        return [float(v) for v in value]
    return value


def _declare(node: Node, spec: ParameterSpec, source: str) -> None:
    try:
        node.declare_parameter(spec.name, _as_declared(spec, spec.default), describe(spec))
        return
    except ParameterException as exc:
        refusal = str(exc)
    # Read what the params file or -p offered, to say what is wrong in the schema's words, or
    # to take an integer for the double it names (YAML's 2400 for 2400.0) as the CLI does.
    offered = node.declare_parameter(
        spec.name, None, ParameterDescriptor(dynamic_typing=True)
    ).value
    node.undeclare_parameter(spec.name)
    problem = spec.problem(offered)
    if problem is not None:
        raise ConfigError(source, spec.name, problem)
    try:
        value = _as_declared(spec, offered)
        node.declare_parameter(spec.name, value, describe(spec), ignore_override=True)
    except (ParameterException, TypeError, ValueError):
        raise ConfigError(source, spec.name, refusal) from None


def declare_parameters(
    node: Node, schema: ParameterSchema, on_change: ChangeHook | None = None
) -> dict[str, Any]:
    """Declares every parameter of ``schema`` on ``node`` and installs the on-set check.

    Args:
        node: The node (its parameter overrides hold ``--params-file`` and ``-p``).
        schema: The node's parameters.
        on_change: Called with the changes the schema accepted on a later set (not at
            declaration); returns ``None`` to accept them (having applied them), or why not.

    Returns:
        The values, by name.

    Raises:
        ConfigError: A value is of the wrong type or out of range, naming the parameter.
    """
    source = f'{node.get_name()} parameters'
    for spec in schema:
        _declare(node, spec, source)
    values = {spec.name: node.get_parameter(spec.name).value for spec in schema}
    for spec in schema:
        problem = spec.problem(values[spec.name])
        if problem is not None:
            raise ConfigError(source, spec.name, problem)

    def on_set(parameters: list[Parameter]) -> SetParametersResult:
        changes = {p.name: p.value for p in parameters if p.name in schema}
        reason = schema.first_problem(changes)
        if reason is None and on_change is not None and changes:
            reason = on_change(changes)
        return SetParametersResult(successful=reason is None, reason=reason or '')

    node.add_on_set_parameters_callback(on_set)
    return values


def undeclared_in_schema(node: Node, schema: ParameterSchema) -> list[str]:
    """The parameters ``node`` declares that ``schema`` does not (rclpy's own left out)."""
    names = node.list_parameters([], 0).names
    return sorted(
        name
        for name in names
        if name not in schema
        and name not in RCLPY_PARAMETERS
        and not name.startswith(RCLPY_PREFIXES)
    )


class SchemaNode(Node):
    """A node named by its parameter schema, with every parameter of it declared.

    The constructor every node of the package shares: the schema names the node, the
    overrides and ``--ros-args`` (``--params-file``, ``-p``, remaps) are taken as rclpy takes
    them, and :func:`declare_parameters` declares and checks the values.

    Args:
        schema: The node's parameters (and its name).
        on_change: See :func:`declare_parameters`.
        **options: The node's :class:`NodeOptions` (context, overrides, namespace,
            ``--ros-args``).

    A schema with :data:`~lumpbeam_ros.nodes.realtime.REALTIME_PRIORITY` has the node's threads
    put on that real-time priority (or a warning saying why not).

    Attributes:
        parameter_values: The declared values, by name.
        refusals: Values refused per topic (:meth:`refuse`).

    Raises:
        ConfigError: A value is of the wrong type or out of range, naming the parameter.
    """

    #: Seconds between two warnings about values refused on one topic.
    REFUSAL_WARN_PERIOD_S = 5.0

    def __init__(
        self,
        schema: ParameterSchema,
        on_change: ChangeHook | None = None,
        **options: Unpack[NodeOptions],
    ):
        parameter_overrides = options.get('parameter_overrides')
        cli_args = options.get('cli_args')
        if isinstance(parameter_overrides, Mapping):
            overrides = [Parameter(k, value=v) for k, v in parameter_overrides.items()]
        else:
            overrides = list(parameter_overrides or [])
        super().__init__(
            schema.node,
            context=options.get('context'),
            namespace=options.get('namespace', ''),
            cli_args=list(cli_args) if cli_args is not None else None,
            parameter_overrides=overrides,
        )
        self.parameter_values = declare_parameters(self, schema, on_change)
        self.refusals: Counter[str] = Counter()
        self._refused_at: dict[str, float] = {}
        for name in sorted(self._parameter_overrides):
            if not self.has_parameter(name) and not name.startswith('qos_overrides.'):
                self.get_logger().warning(
                    f'unknown parameter {name!r}: not a parameter of {schema.node} '
                    f'(--help lists them); ignored'
                )
        if REALTIME_PRIORITY.name in self.parameter_values:
            # A schema that declares it has it applied here, before the node's own set-up.
            problem = set_realtime_priority(int(self.parameter_values[REALTIME_PRIORITY.name]))
            if problem:
                self.get_logger().warning(problem)

    def refuse(self, topic: str, refused: str, kept: str) -> None:
        """Refuses what a message brought: the one rule of every node for a bad value.

        A value the physics or the declared parameters do not allow (a load the beam cannot
        carry, a stiffness or a mode no model or shaper can take, a malformed message) never
        reaches a solver and never changes the node's state: the last good state is kept,
        the refusal is counted per topic, and a warning naming the topic, the value and what
        was kept is logged at most every :attr:`REFUSAL_WARN_PERIOD_S` per topic.

        Args:
            topic: Where the value came from.
            refused: The value and why it is refused, e.g. ``'1e+06 kg: not carried'``.
            kept: What the node keeps instead, e.g. ``'keeping 4.5 kg'``.
        """
        self.refusals[topic] += 1
        now = time.monotonic()
        if now - self._refused_at.get(topic, -math.inf) < self.REFUSAL_WARN_PERIOD_S:
            return
        self._refused_at[topic] = now
        self.get_logger().warning(
            f'{topic}: {refused}; {kept} ({self.refusals[topic]} refused so far)'
        )
