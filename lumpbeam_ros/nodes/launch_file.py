"""ROS 2 YAML launch files read without ROS's ``launch``: what ``lumpbeam launch`` starts.

The files under ``launch/`` are ordinary ROS 2 launch files in the YAML frontend's format, so
``ros2 launch lumpbeam_ros drop_test.launch.yaml`` runs them on a full ROS install; where ROS
comes from pip (no ``launch`` package), ``lumpbeam launch FILE`` reads them here and starts
the same nodes. The tags and attributes read are the frontend's documented ones, a subset:

- ``arg`` (``name``, ``default``, ``description``): set from the command line as
  ``NAME:=VALUE``;
- ``node`` (``pkg``, ``exec``, ``name``, ``namespace``, ``output``, ``args``, ``ros_args``,
  ``param`` as ``name``/``value`` pairs or ``from`` a parameter file, ``remap`` as
  ``from``/``to`` pairs);
- substitutions ``$(var NAME)``, ``$(env NAME)``, ``$(env NAME DEFAULT)`` and
  ``$(find-pkg-share lumpbeam_ros)``.

Anything else (another tag, another package's node, another substitution) is one clear error
that names it: ``ros2 launch`` is the tool for those files.
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.base.interface import NODE_NAMES
from lumpbeam_ros.base.paramfile import read_yaml_document
from lumpbeam_ros.base.resources import PACKAGE, share_dir

#: The attributes read of each tag (the YAML frontend's names).
NODE_KEYS = frozenset(
    {'pkg', 'exec', 'name', 'namespace', 'output', 'args', 'ros_args', 'param', 'remap'}
)
ARG_KEYS = frozenset({'name', 'default', 'description'})
#: ``output`` values: where a node's output goes (both are the terminal here).
OUTPUTS = ('screen', 'log', 'both')

_SUBSTITUTION = re.compile(r'\$\(([^()]*)\)')


@dataclass(frozen=True)
class NodeLaunch:
    """One node of a launch file, resolved.

    Attributes:
        executable: The node's executable (``identifier_node``).
        name: The node's name, when the file renames it (empty: its own).
        namespace: Its namespace (empty: none).
        args: Arguments before ``--ros-args``.
        ros_args: ``--ros-args`` arguments: parameter files, parameters, remaps.
    """

    executable: str
    name: str = ''
    namespace: str = ''
    args: tuple[str, ...] = ()
    ros_args: tuple[str, ...] = ()

    @property
    def label(self) -> str:
        """How the node is named in messages: its name, else its executable."""
        return self.name or self.executable

    def argv(self) -> list[str]:
        """The node's command-line arguments, as ``ros2 launch`` would give them."""
        ros = []
        if self.name:
            ros += ['-r', f'__node:={self.name}']
        if self.namespace:
            ros += ['-r', f'__ns:={self.namespace}']
        ros += list(self.ros_args)
        return [*self.args, '--ros-args', *ros] if ros else list(self.args)


@dataclass(frozen=True)
class LaunchPlan:
    """A launch file resolved: its arguments' values and the nodes to start.

    Attributes:
        source: The file.
        arguments: Every declared argument's value.
        nodes: The nodes, in the file's order.
    """

    source: Path
    arguments: Mapping[str, str]
    nodes: tuple[NodeLaunch, ...]


def parse_assignments(texts: Sequence[str]) -> dict[str, str]:
    """``NAME:=VALUE`` words of a command line, as ``ros2 launch`` takes them.

    Raises:
        LumpbeamError: A word that is not ``NAME:=VALUE``.
    """
    values = {}
    for text in texts:
        name, sep, value = text.partition(':=')
        if not sep or not re.fullmatch(r'[A-Za-z_][A-Za-z0-9_]*', name):
            raise LumpbeamError(f'launch argument {text!r}: expected NAME:=VALUE')
        values[name] = value
    return values


def read_launch_file(path: str | Path, given: Mapping[str, str] | None = None) -> LaunchPlan:
    """Reads a ROS 2 YAML launch file into the nodes it starts.

    Args:
        path: The ``.launch.yaml`` file.
        given: Argument values from the command line (``NAME:=VALUE``).

    Returns:
        The plan.

    Raises:
        LumpbeamError: The file is missing or not YAML, uses a tag, an attribute or a
            substitution this reader does not know, starts another package's node, or an
            argument given is not declared or a declared one has no value.
    """
    path = Path(path)
    document = read_yaml_document(path)
    entries = document.get('launch') if isinstance(document, Mapping) else None
    if not isinstance(entries, list):
        raise LumpbeamError(f'{path}: not a ROS 2 YAML launch file (no top-level launch: list)')
    given = dict(given or {})
    arguments: dict[str, str] = {}
    nodes = []
    for i, entry in enumerate(entries):
        where = f'{path}: launch[{i}]'
        if not isinstance(entry, Mapping) or len(entry) != 1:
            raise LumpbeamError(f'{where}: expected one tag (arg: or node:)')
        ((tag, body),) = entry.items()
        if not isinstance(body, Mapping):
            raise LumpbeamError(f'{where}: {tag}: expected a mapping of attributes')
        if tag == 'arg':
            name, value = _argument(body, where, given, arguments)
            arguments[name] = value
        elif tag == 'node':
            nodes.append(_node(body, f'{where} (node)', arguments))
        else:
            raise LumpbeamError(
                f'{where}: tag {tag!r} is not read by lumpbeam launch (arg, node); '
                'run the file with ros2 launch'
            )
    unknown = sorted(set(given) - set(arguments))
    if unknown:
        declared = ', '.join(sorted(arguments)) or 'none'
        raise LumpbeamError(f'{path}: no launch argument {unknown[0]!r} (declared: {declared})')
    if not nodes:
        raise LumpbeamError(f'{path}: starts no node')
    return LaunchPlan(path, arguments, tuple(nodes))


def _argument(
    body: Mapping[str, Any], where: str, given: Mapping[str, str], known: Mapping[str, str]
) -> tuple[str, str]:
    _check_keys(body, ARG_KEYS, f'{where} (arg)')
    name = str(body.get('name', ''))
    if not name:
        raise LumpbeamError(f'{where}: arg without a name')
    if name in given:
        return name, given[name]
    if 'default' not in body:
        raise LumpbeamError(f'{where}: launch argument {name!r} has no default: give {name}:=...')
    return name, substitute(str(body['default']), known, where)


def _node(body: Mapping[str, Any], where: str, arguments: Mapping[str, str]) -> NodeLaunch:
    _check_keys(body, NODE_KEYS, where)

    def text(key: str) -> str:
        return substitute(str(body.get(key, '')), arguments, f'{where} {key}')

    if text('pkg') != PACKAGE:
        raise LumpbeamError(
            f'{where}: pkg {text("pkg")!r}: lumpbeam launch starts {PACKAGE} nodes only; '
            'run the file with ros2 launch'
        )
    executable = text('exec')
    if executable not in NODE_NAMES:
        raise LumpbeamError(
            f'{where}: exec {executable!r} is not a node of {PACKAGE} ({", ".join(NODE_NAMES)})'
        )
    output = text('output') or 'screen'
    if output not in OUTPUTS:
        raise LumpbeamError(f'{where}: output {output!r}: one of {", ".join(OUTPUTS)}')
    ros_args: list[str] = text('ros_args').split()
    for j, param in enumerate(_list(body.get('param', []), f'{where} param')):
        ros_args += _param(param, arguments, f'{where} param[{j}]')
    for j, remap in enumerate(_list(body.get('remap', []), f'{where} remap')):
        _check_keys(remap, frozenset({'from', 'to'}), f'{where} remap[{j}]')
        source = substitute(str(remap.get('from', '')), arguments, f'{where} remap[{j}]')
        target = substitute(str(remap.get('to', '')), arguments, f'{where} remap[{j}]')
        if not source or not target:
            raise LumpbeamError(f'{where}: remap[{j}] needs from: and to:')
        ros_args += ['-r', f'{source}:={target}']
    return NodeLaunch(
        executable, text('name'), text('namespace'), tuple(text('args').split()), tuple(ros_args)
    )


def _param(param: Any, arguments: Mapping[str, str], where: str) -> list[str]:
    if not isinstance(param, Mapping):
        raise LumpbeamError(f'{where}: expected name: and value:, or from:')
    if 'from' in param:
        _check_keys(param, frozenset({'from'}), where)
        return ['--params-file', substitute(str(param['from']), arguments, where)]
    _check_keys(param, frozenset({'name', 'value'}), where)
    if 'name' not in param or 'value' not in param:
        raise LumpbeamError(f'{where}: expected name: and value:, or from:')
    value = param['value']
    text = str(value).lower() if isinstance(value, bool) else str(value)
    return ['-p', f'{param["name"]}:={substitute(text, arguments, where)}']


def substitute(text: str, arguments: Mapping[str, str], where: str) -> str:
    """Resolves the substitutions ``$(var ...)``, ``$(env ...)`` and ``$(find-pkg-share ...)``.

    Raises:
        LumpbeamError: Another substitution, an undeclared argument, an unset variable
            without a default, or another package's share.
    """

    def resolve(match: re.Match[str]) -> str:
        kind, *words = match.group(1).split()
        if kind == 'var' and len(words) == 1:
            if words[0] not in arguments:
                raise LumpbeamError(f'{where}: $(var {words[0]}): no such launch argument')
            return arguments[words[0]]
        if kind == 'env' and len(words) in (1, 2):
            value = os.environ.get(words[0], words[1] if len(words) == 2 else None)
            if value is None:
                raise LumpbeamError(f'{where}: $(env {words[0]}): not set, and no default')
            return value
        if kind == 'find-pkg-share' and words == [PACKAGE]:
            return str(share_dir())
        raise LumpbeamError(f'{where}: substitution {match.group(0)} is not read here')

    return _SUBSTITUTION.sub(resolve, text)


def _list(value: Any, where: str) -> list[Any]:
    if not isinstance(value, list):
        raise LumpbeamError(f'{where}: expected a list')
    return value


def _check_keys(body: Mapping[str, Any], allowed: frozenset[str], where: str) -> None:
    unknown = sorted(set(body) - allowed)
    if unknown:
        raise LumpbeamError(f'{where}: attribute {unknown[0]!r} is not read by lumpbeam launch')
