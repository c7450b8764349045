"""Counts that show whether the codebase keeps one way to do each thing.

Usage: ``python tools/design_counts.py [REPO]``. Prints, one line each:

- names of the interface (topics, frames, status and node names) written as string literals
  outside ``lumpbeam_ros/base/interface.py`` (docstrings and comments do not count; the camera
  frame's name, the word ``'camera'``, also labels the camera among the sensors and is left
  out);
- how nodes get their parameters: ``declare_parameter`` calls outside the one schema-driven
  adapter (``nodes/ros_parameters.py``);
- tip-series types: classes that hold their own ``z: np.ndarray`` column;
- readers that decode ``/tip_pose`` from a bag (``pose_values(`` calls outside the node
  callbacks);
- core modules without a test module (``tools/test_modules.py``);
- node parameters whose literal default or bound is written in more than one place;
- node parameters declared but never read by what the node runs;
- places that must change to add an effect, besides its physics;
- lab modules (``lumpbeam_lab``: benchmarks, the validation renderer, scoring against
  truth, the MCAP doctor) imported by the product outside the commands that run them;
- readers of bags: places that read MCAP records or CDR themselves (or through another
  bag reader) outside the one reader (``bagio/reader.py``, on the ``mcap`` package) and the
  fast path kept beside it with its agreement test (``bagio/fastscan.py``);
- configuration types named against the naming rule (doc/architecture.md, "Names");
- imports that run back up the floors (:class:`Floors`: ``lumpbeam_ros.__all__`` and the
  order of each floor's packages), a rule ``test/test_layers.py`` holds module by module;
- twins: a concept with one home (:data:`TWINS`) done again elsewhere.

mypy's count is its own command: ``mypy`` (the configuration is ``mypy.ini``).
"""

from __future__ import annotations

import ast
import importlib
import importlib.util
import io
import re
import sys
import tokenize
from pathlib import Path
from typing import Any


def _load(path: Path, name: str) -> object:
    spec = importlib.util.spec_from_file_location(name, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def interface_names(repo: Path) -> set[str]:
    """The string constants ``lumpbeam_ros/base/interface.py`` declares (names, not types)."""
    tree = ast.parse((repo / 'lumpbeam_ros' / 'base' / 'interface.py').read_text())
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Assign | ast.AnnAssign) and isinstance(node.value, ast.Constant):
            value = node.value.value
            if isinstance(value, str) and '/msg/' not in value:
                names.add(value)
    return names - {'camera'}


def _docstring_lines(tree: ast.Module) -> set[int]:
    lines: set[int] = set()
    for node in ast.walk(tree):
        body = getattr(node, 'body', None)
        if isinstance(body, list) and body and isinstance(body[0], ast.Expr):
            value = body[0].value
            if isinstance(value, ast.Constant) and isinstance(value.value, str):
                lines.update(range(value.lineno, (value.end_lineno or value.lineno) + 1))
    return lines


def _all_lines(tree: ast.Module) -> set[int]:
    """The lines of a package's ``__all__`` (module names, which may be a node's name)."""
    lines: set[int] = set()
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(
            isinstance(target, ast.Name) and target.id == '__all__' for target in node.targets
        ):
            lines.update(range(node.lineno, (node.end_lineno or node.lineno) + 1))
    return lines


def literal_uses(repo: Path) -> list[str]:
    """``file:line: 'name'`` for each interface name written as a literal outside it."""
    names = interface_names(repo)
    found = []
    for path in sorted((repo / 'lumpbeam_ros').rglob('*.py')):
        if path.name == 'interface.py' and path.parent.name == 'base':
            continue
        text = path.read_text()
        tree = ast.parse(text)
        skip = _docstring_lines(tree) | _all_lines(tree)
        for token in tokenize.generate_tokens(io.StringIO(text).readline):
            if token.type != tokenize.STRING or token.start[0] in skip:
                continue
            try:
                value = ast.literal_eval(token.string)
            except (ValueError, SyntaxError):
                continue
            if value in names:
                found.append(f'{path.relative_to(repo)}:{token.start[0]}: {token.string}')
    return found


def _grep(repo: Path, pattern: str, exclude: tuple[str, ...] = ()) -> list[str]:
    regex = re.compile(pattern)
    hits = []
    for path in sorted((repo / 'lumpbeam_ros').rglob('*.py')):
        rel = path.relative_to(repo).as_posix()
        if rel in exclude:
            continue
        for number, line in enumerate(path.read_text().splitlines(), 1):
            if regex.search(line):
                hits.append(f'{rel}:{number}: {line.strip()}')
    return hits


# --- One home for every concept: parameters, effects, the lab ---------------------------------

#: Where node parameters are declared and merely carried (not a reader of any of them).
PLUMBING = (
    'lumpbeam_ros/nodes/params/',
    'lumpbeam_ros/base/paramfile.py',
    'lumpbeam_ros/nodes/ros_parameters.py',
)

#: The lab: what proves the product (benchmarks, the validation renderer, accuracy scoring
#: against truth), a package of its own beside ``lumpbeam_ros``, not installed.
LAB = 'lumpbeam_lab'

#: Example cases of the product's synthetic data and demo (hidden effects to find): left out
#: of the places that must change to add an effect.
_EXAMPLES = ('lumpbeam_ros/apps/demo/', 'lumpbeam_ros/core/synthetic/')

#: No part of the product imports the lab: ``lumpbeam bench`` finds it in the checkout at run
#: time (``importlib``), so an installed wheel runs without it.
_RUNS_THE_LAB: tuple[str, ...] = ()

_NODE_MODULES = {
    'camera_node': 'camera_node',
    'identifier_node': 'identifier_node',
    'simulator_node': 'simulator_node',
    'diagnosis_node': 'diagnosis_node',
}


def _sources(repo: Path) -> dict[str, ast.Module]:
    """Every module of the package, parsed, by its path relative to ``repo``."""
    return {
        path.relative_to(repo).as_posix(): ast.parse(path.read_text())
        for path in sorted((repo / 'lumpbeam_ros').rglob('*.py'))
    }


def _schemas(repo: Path) -> list[Any]:
    """The nodes' parameter schemas (``nodes.params.reference.SCHEMAS``) of ``repo``."""
    loaded = sys.modules.get('lumpbeam_ros')
    if loaded is None or Path(str(loaded.__file__)).resolve().parents[1] != repo.resolve():
        # Another tree's package (a stash, a worktree) is imported afresh from ``repo``.
        for name in [m for m in sys.modules if m.split('.')[0] == 'lumpbeam_ros']:
            del sys.modules[name]
        sys.path.insert(0, str(repo))
    reference = importlib.import_module('lumpbeam_ros.nodes.params.reference')
    return list(reference.SCHEMAS)


def _field_names(sources: dict[str, ast.Module]) -> dict[str, str]:
    """Dotted parameter name -> the core field that holds it under another name.

    A configuration field renamed from its key is declared by a ``PARAMETER_KEYS`` table
    (``{'window_s': 'window.length_s'}``) or by a field whose declaration names its key
    (``window_s: float = setting('window.length_s', ...)``).
    """
    renamed: dict[str, str] = {}
    for tree in sources.values():
        for node in ast.walk(tree):
            if (
                isinstance(node, ast.Assign | ast.AnnAssign)
                and isinstance(node.value, ast.Dict)
                and 'PARAMETER_KEYS' in ast.unparse(node).split('=')[0]
            ):
                for key, value in zip(node.value.keys, node.value.values, strict=True):
                    if isinstance(key, ast.Constant) and isinstance(value, ast.Constant):
                        renamed[str(value.value)] = str(key.value)
            if (
                isinstance(node, ast.AnnAssign)
                and isinstance(node.target, ast.Name)
                and isinstance(node.value, ast.Call)
                and node.value.args
                and isinstance(node.value.args[0], ast.Constant)
                and isinstance(node.value.args[0].value, str)
            ):
                renamed.setdefault(str(node.value.args[0].value), node.target.id)
    return renamed


def _numbers(value: Any) -> set[float]:
    if isinstance(value, bool) or isinstance(value, str):
        return set()
    if isinstance(value, int | float):
        return {float(value)}
    if isinstance(value, tuple | list):
        return {float(v) for v in value}
    return set()


def _literal_numbers(node: ast.AST) -> set[float]:
    """The numbers written as literals in an expression (``-1.5`` and ``(0.0, 0.05)`` too)."""
    out = set()
    for sub in ast.walk(node):
        if isinstance(sub, ast.Constant) and isinstance(sub.value, int | float):
            if not isinstance(sub.value, bool):
                out.add(float(sub.value))
        if (
            isinstance(sub, ast.UnaryOp)
            and isinstance(sub.op, ast.USub)
            and isinstance(sub.operand, ast.Constant)
            and isinstance(sub.operand.value, int | float)
        ):
            out.add(-float(sub.operand.value))
    return out


def _literal_places(
    sources: dict[str, ast.Module],
) -> tuple[list[tuple[str, ast.Call]], list[tuple[str, str, int, set[float]]]]:
    """Calls naming a string, and names given a literal number (fields, arguments)."""
    calls, named = [], []
    for rel, tree in sources.items():
        for node in ast.walk(tree):
            if isinstance(node, ast.Call) and any(
                isinstance(a, ast.Constant) and isinstance(a.value, str) for a in node.args
            ):
                calls.append((rel, node))
            elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
                if isinstance(node.value, ast.Constant | ast.Tuple | ast.UnaryOp):
                    numbers = _literal_numbers(node.value)
                    if numbers:
                        named.append((rel, node.target.id, node.lineno, numbers))
            elif isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                args = node.args.args[len(node.args.args) - len(node.args.defaults) :]
                for arg, default in zip(args, node.args.defaults, strict=True):
                    if isinstance(default, ast.Constant | ast.Tuple | ast.UnaryOp):
                        numbers = _literal_numbers(default)
                        if numbers:
                            named.append((rel, arg.arg, default.lineno, numbers))
    return calls, named


def repeated_parameter_literals(repo: Path) -> list[str]:
    """Node parameters whose default or bound is written as a literal in more than one place.

    A place is a call that names the parameter's key and writes a number of its default or
    bounds (a schema declaration, a loader's ``get_float(params, key, source, 2400.0)``), or a
    class attribute or function argument named after the parameter (its last dotted part or
    its core field) whose literal default is the parameter's. The parameter files under
    ``config/`` are not counted: a test holds each equal to its schema. Nor are the effects'
    parameters (``effects.*``): their defaults are the effects' "off" values, which the count
    of places to add an effect covers.

    Returns:
        ``node key: place, place, ...`` for each such parameter.
    """
    sources = _sources(repo)
    fields = _field_names(sources)
    calls, named = _literal_places(sources)
    found = []
    for schema in _schemas(repo):
        for spec in schema:
            if spec.name.startswith('effects.'):
                continue
            values = _numbers(spec.default)
            bounds = spec.bounds
            ends = (
                [] if bounds is None else [b for b in (bounds.low, bounds.high) if b is not None]
            )
            limits = _numbers(ends)
            names = {spec.name.rpartition('.')[2], fields.get(spec.name, '')} - {''}
            places = set()
            for rel, call in calls:
                if not any(
                    isinstance(a, ast.Constant) and a.value == spec.name for a in call.args
                ):
                    continue
                written: set[float] = set()
                for arg in [*call.args, *(k.value for k in call.keywords)]:
                    written |= _literal_numbers(arg)
                flags = {k.arg for k in call.keywords} & {'positive', 'non_negative', 'minimum'}
                if written & (values | limits) or flags:
                    places.add(f'{rel}:{call.lineno}')
            # A zero default (none, off) is no chosen value: only others count by name.
            for rel, name, line, numbers in named:
                if name in names and values - {0.0} and numbers <= values:
                    places.add(f'{rel}:{line}')
            if len(places) > 1:
                found.append(f'{schema.node} {spec.name}: {", ".join(sorted(places))}')
    return found


def _imported(tree: ast.Module) -> set[str]:
    """The package's modules a module imports (``lumpbeam_ros/x/y.py`` paths, or packages)."""
    out = set()
    for node in ast.walk(tree):
        names: list[str] = []
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = [node.module, *(f'{node.module}.{a.name}' for a in node.names)]
        elif isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        for name in names:
            if name.startswith('lumpbeam_ros'):
                out.add(name.replace('.', '/'))
    return out


def _closure(sources: dict[str, ast.Module], start: str) -> set[str]:
    """The modules ``start`` imports, directly or not (itself included)."""
    seen, todo = set(), [start]
    while todo:
        rel = todo.pop()
        if rel in seen or rel not in sources:
            continue
        seen.add(rel)
        for name in _imported(sources[rel]):
            for candidate in (f'{name}.py', f'{name}/__init__.py'):
                if candidate in sources:
                    todo.append(candidate)
    return seen


def _loaders(tree: ast.Module) -> set[int]:
    """Lines of the functions that only carry parameters into a configuration object."""
    lines: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.FunctionDef) and (
            node.name.endswith(('_from_parameters', '_to_parameters'))
            or node.name.startswith('load_')
        ):
            lines.update(range(node.lineno, (node.end_lineno or node.lineno) + 1))
    return lines


def unread_parameters(repo: Path) -> list[str]:
    """Node parameters that nothing the node runs reads.

    A parameter is read when code the node imports (directly or not; the parameter plumbing
    and the loaders that only carry values into a configuration object left out) names its
    key, or reads the configuration field that holds it (``config.window_s``). A parameter
    under a section that is a configuration object's field (``synthetic.*`` fills
    ``CameraConfig.synthetic``) is read only when that section is read.

    Returns:
        ``node parameter`` for each one never read.
    """
    sources = _sources(repo)
    fields = _field_names(sources)
    sections = {
        node.target.id
        for tree in sources.values()
        for node in ast.walk(tree)
        if isinstance(node, ast.ClassDef) and node.name.endswith('Config')
        for node in node.body
        if isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name)
    }
    found = []
    for schema in _schemas(repo):
        node_module = f'lumpbeam_ros/nodes/{schema.node}.py'
        closure = {rel for rel in _closure(sources, node_module) if not rel.startswith(PLUMBING)}
        strings: set[str] = set()
        attributes: set[str] = set()
        for rel in closure:
            skip = _loaders(sources[rel])
            for node in ast.walk(sources[rel]):
                if getattr(node, 'lineno', 0) in skip:
                    continue
                if isinstance(node, ast.Constant) and isinstance(node.value, str):
                    strings.add(node.value)
                elif isinstance(node, ast.Attribute):
                    attributes.add(node.attr)
        # A key read whole by its loader (its section carried, not named) counts with it.
        for rel in closure:
            skip = _loaders(sources[rel])
            for node in ast.walk(sources[rel]):
                if getattr(node, 'lineno', 0) in skip and isinstance(node, ast.Constant):
                    if (
                        isinstance(node.value, str)
                        and node.value.partition('.')[0] not in sections
                    ):
                        strings.add(node.value)
        for spec in schema:
            section, _, rest = spec.name.partition('.')
            field = fields.get(spec.name, spec.name.rpartition('.')[2])
            in_section = bool(rest) and section in sections
            if in_section and section not in attributes:
                found.append(f'{schema.node} {spec.name}')
            # A sub-section named by a table (``effects.<name>.*`` through the effect names).
            elif not (
                spec.name in strings
                or field in attributes
                or in_section
                or (spec.name.count('.') > 1 and spec.name.split('.')[1] in strings)
            ):
                found.append(f'{schema.node} {spec.name}')
    return found


def _effect_names(repo: Path) -> tuple[set[str], set[str]]:
    """The effect names and their parameters (the table of ``doc/interfaces.md``)."""
    text = (repo / 'doc' / 'interfaces.md').read_text().partition('## Missing effects')[2]
    rows = re.findall(r'^\| `([a-z_]+)` \| `([a-z0-9_]+)` \|', text.partition('\n## ')[0], re.M)
    return {row[0] for row in rows}, {row[1] for row in rows}


def effect_places(repo: Path) -> list[str]:
    """Places that must change to add an effect, besides its physics.

    A place is a statement of the core (the lab's example cases left out) whose literal
    tables name effects or their parameters (a dict, set, tuple or list with one as a key or
    an element), or a class with a plain field per effect; a sequence of effect records
    (each a call naming its effect) is one place.

    Returns:
        ``file:line: what`` for each place.
    """
    effects, parameters = _effect_names(repo)
    found = []
    for rel, tree in _sources(repo).items():
        if rel.startswith(_EXAMPLES):
            continue
        for statement in ast.walk(tree):
            if isinstance(statement, ast.ClassDef) and statement.name == 'Effects':
                plain = [
                    n.target.id
                    for n in statement.body
                    if isinstance(n, ast.AnnAssign)
                    and isinstance(n.target, ast.Name)
                    and n.target.id in effects | {'coulomb_torque_nm', 'drag_c_q', 'scale_excess'}
                    and not (isinstance(n.value, ast.Call) and _names_effect(n.value, effects))
                ]
                if plain:
                    found.append(f'{rel}:{statement.lineno}: class Effects, a field per effect')
            if not isinstance(statement, ast.Assign | ast.AnnAssign | ast.Return | ast.Expr):
                continue
            named: set[str] = set()
            for node in ast.walk(statement):
                elements: list[ast.AST] = []
                if isinstance(node, ast.Dict):
                    elements = [k for k in node.keys if k is not None]
                elif isinstance(node, ast.Set | ast.Tuple | ast.List):
                    elements = list(node.elts)
                    elements += [
                        e.args[0] for e in node.elts if isinstance(e, ast.Call) and e.args
                    ]
                named |= {
                    str(e.value)
                    for e in elements
                    if isinstance(e, ast.Constant) and e.value in effects | parameters
                }
            # A parameter's name alone (``mass_kg``) may be another key's; two are a table.
            if named & effects or len(named & parameters) > 1:
                found.append(f'{rel}:{statement.lineno}: a table naming {len(named)}')
    return found


def _names_effect(call: ast.Call, effects: set[str]) -> bool:
    """Whether a call declares an effect record (its name a literal argument, maybe nested)."""
    return any(
        isinstance(a, ast.Constant) and a.value in effects
        for arg in call.args
        for a in ast.walk(arg)
    )


def lab_imports(repo: Path) -> list[str]:
    """Imports of the lab (:data:`LAB`) by the product (the core, the nodes, the demo).

    Only the commands that run the lab (:data:`_RUNS_THE_LAB`) may import it.

    Returns:
        ``file:line: module`` for each.
    """
    found = []
    lab_names = (LAB,)
    for rel, tree in _sources(repo).items():
        if rel.startswith(_RUNS_THE_LAB):
            continue
        for node in ast.walk(tree):
            modules: list[str] = []
            if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                modules = [node.module, *(f'{node.module}.{a.name}' for a in node.names)]
            elif isinstance(node, ast.Import):
                modules = [a.name for a in node.names]
            hits = sorted(
                {m for m in modules if any(m == n or m.startswith(f'{n}.') for n in lab_names)}
            )
            if hits:
                found.append(f'{rel}:{node.lineno}: {hits[0]}')
    return found


# --- One reader of bags ------------------------------------------------------------------------

#: The one reader of bags: it may import mcap's record-level readers, and parses no bytes itself.
THE_READER = 'lumpbeam_ros/core/bagio/reader.py'
#: The type system: rosbags' CDR deserializer is called here, and only here.
_TYPE_SYSTEM = 'lumpbeam_ros/core/bagio/typestore.py'
#: The fast path kept beside the reader, and the test that it agrees with the library
#: message for message (without the test, the fast path counts).
FAST_PATH = ('lumpbeam_ros/core/bagio/fastscan.py', 'test/core/bagio/test_fastscan.py')

#: Modules that parse MCAP records, or read bags, on their own: mcap's record-level readers
#: and rosbags' bag readers and deserializers.
_READING_MODULES = (
    'mcap.reader',
    'mcap.stream_reader',
    'mcap.data_stream',
    'rosbags.rosbag2.reader',
    'rosbags.highlevel',
    'rosbags.serde',
)

#: Calls that take bytes apart by hand (CDR offsets, MCAP fields).
_BYTE_PARSING = re.compile(
    r'\bstruct\.(unpack|unpack_from|iter_unpack|Struct)\(|\.unpack_from\(|int\.from_bytes\('
    r'|deserialize_cdr\(|\bReader\(|AnyReader\(|\\x89MCAP'
)


def bag_readers(repo: Path) -> list[str]:
    """Places that parse MCAP records or CDR outside the one reader and its fast path.

    A place is an import of a record-level reader (:data:`_READING_MODULES`, or rosbags'
    ``Reader``) outside :data:`THE_READER`, or a line that takes bytes apart by hand
    (``struct`` unpacking, ``int.from_bytes``, a ``deserialize_cdr`` call, the MCAP magic)
    anywhere, the one reader included, in either package. The fast path counts too once its
    agreement test is gone.

    Returns:
        ``file:line: what`` for each place.
    """
    found = []
    for package in ('lumpbeam_ros', LAB):
        for path in sorted((repo / package).rglob('*.py')):
            rel = path.relative_to(repo).as_posix()
            tested = rel == FAST_PATH[0] and (repo / FAST_PATH[1]).exists()
            if rel == _TYPE_SYSTEM or tested:
                continue
            text = path.read_text()
            tree = ast.parse(text)
            for node in ast.walk(tree):
                if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                    names = [node.module, *(f'{node.module}.{a.name}' for a in node.names)]
                elif isinstance(node, ast.Import):
                    names = [a.name for a in node.names]
                else:
                    continue
                hits = [
                    n for n in names if n.startswith(_READING_MODULES) or n.endswith('.Reader')
                ]
                if hits and rel != THE_READER:
                    found.append(f'{rel}:{node.lineno}: import {hits[0]}')
            skip = _docstring_lines(tree)
            for number, line in enumerate(text.splitlines(), 1):
                if number not in skip and _BYTE_PARSING.search(line.split('#')[0]):
                    found.append(f'{rel}:{number}: {line.strip()}')
    return found


# --- Names of configuration types --------------------------------------------------------------


def _declared_keys(node: ast.ClassDef) -> list[str]:
    """The parameter keys a class's fields declare with ``setting('key', ...)``."""
    keys = []
    for item in node.body:
        if (
            isinstance(item, ast.AnnAssign)
            and isinstance(item.value, ast.Call)
            and isinstance(item.value.func, ast.Name)
            and item.value.func.id == 'setting'
            and item.value.args
            and isinstance(item.value.args[0], ast.Constant)
        ):
            keys.append(str(item.value.args[0].value))
    return keys


def config_type_names(repo: Path) -> list[str]:
    """Configuration types named against the rule of doc/architecture.md, "Names".

    - no type ends in ``Params`` (``Parameters``, spelled out, is a model's quantities);
    - a ``Settings`` type is one section of a configuration: its fields declare parameters,
      all under one key prefix (``sensor.*``);
    - an ``Options`` type declares no parameter (it is never read from a parameter file);
    - a type that declares parameters ends in ``Config``, ``Settings`` or ``Parameters``.

    Returns:
        ``file:line: name: what is wrong`` for each.
    """
    found = []
    for package in ('lumpbeam_ros', LAB):
        for path in sorted((repo / package).rglob('*.py')):
            rel = path.relative_to(repo).as_posix()
            for node in ast.walk(ast.parse(path.read_text())):
                if not isinstance(node, ast.ClassDef):
                    continue
                keys = _declared_keys(node)
                prefixes = {key.partition('.')[0] for key in keys if '.' in key}
                why = ''
                if node.name.endswith('Params'):
                    why = "Params: a model's quantities are Parameters; a configuration, Config"
                elif node.name.endswith('Settings') and (
                    not keys or len(prefixes) != 1 or not all('.' in key for key in keys)
                ):
                    why = 'Settings are one section of parameters, under one key prefix'
                elif node.name.endswith('Options') and keys:
                    why = 'Options are not read from a parameter file'
                elif keys and not node.name.endswith(('Config', 'Settings', 'Parameters')):
                    why = 'it declares parameters: a Config, Settings or Parameters'
                if why:
                    found.append(f'{rel}:{node.lineno}: {node.name}: {why}')
    return found


# --- Imports point down the floors -------------------------------------------------------------


def _constant(package: Path, name: str) -> Any:
    """A constant a package's ``__init__.py`` assigns, read without importing it (or None)."""
    tree = ast.parse((package / '__init__.py').read_text())
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(
            isinstance(target, ast.Name) and target.id == name for target in node.targets
        ):
            return ast.literal_eval(node.value)
    return None


def public_names(package: Path) -> list[str]:
    """A package's ``__all__``, read from its ``__init__.py`` without importing it."""
    return [str(name) for name in _constant(package, '__all__') or []]


class Floors:
    """The package's floors and the order inside them, as the ``__all__`` lists declare them.

    ``lumpbeam_ros.__all__`` lists the floors bottom first; a floor that says it is
    ``LAYERED`` (``core``, ``apps``) orders its ``__all__`` the same way. A module may import
    its own floor and those below; inside an ordered floor, its own package and those listed
    before it.
    The lab (``lumpbeam_lab``) stands above every floor.

    Args:
        repo: The repository.
    """

    def __init__(self, repo: Path):
        package = repo / 'lumpbeam_ros'
        self.floors = tuple(public_names(package))
        self.ordered = {
            floor: tuple(names)
            for floor in self.floors
            if len(names := public_names(package / floor)) > 1
            and all(
                (package / floor / name / '__init__.py').is_file()
                or (package / floor / f'{name}.py').is_file()
                for name in names
            )
            and floor in ('core', 'apps')
        }

    def rank(self, module: str) -> tuple[int, int]:
        """Where a module stands: its floor, and its package's place inside its floor."""
        parts = module.split('.')
        if parts[0] == LAB:
            return (len(self.floors), 0)
        if len(parts) == 1 or parts[1] not in self.floors:
            return (0, 0)
        order = self.ordered.get(parts[1], ())
        inside = order.index(parts[2]) if len(parts) > 2 and parts[2] in order else 0
        return (self.floors.index(parts[1]), inside)

    def may_import(self, module: str, name: str) -> bool:
        """Whether ``module`` may import ``name``: its own floor or one below, never above."""
        mine, theirs = self.rank(module), self.rank(name)
        if theirs[0] != mine[0]:
            return theirs[0] < mine[0]
        return theirs[1] <= mine[1]


def imported_names(path: Path) -> set[str]:
    """Every module a source file imports, at the top or inside functions."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text(encoding='utf-8'))):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module)
    return names


def imports_back_up(repo: Path) -> list[str]:
    """Imports that run back up the floors, or back up the core's or the apps' order.

    Returns:
        ``module imports name`` for each.
    """
    floors = Floors(repo)
    found = []
    for package in ('lumpbeam_ros', LAB):
        for path in sorted((repo / package).rglob('*.py')):
            module = '.'.join(path.relative_to(repo).with_suffix('').parts)
            module = module.removesuffix('.__init__')
            for name in sorted(imported_names(path)):
                ours = name.partition('.')[0] in {'lumpbeam_ros', LAB} and name != 'lumpbeam_ros'
                if ours and not floors.may_import(module, name):
                    found.append(f'{module} imports {name}')
    return found


# --- Twins: one of each ------------------------------------------------------------------------

#: Each concept with its one home, and a pattern that, outside that home, is a second one.
TWINS: dict[str, tuple[str, str]] = {
    # Reading a JointTrajectory message's points.
    'trajectory message conversions': (
        'lumpbeam_ros/nodes/trajectory_messages.py',
        r'\.time_from_start\b',
    ),
    # A parameter file read, or the package's own when none is given.
    'config loaders': ('lumpbeam_ros/base/paramfile.py', r'config_path\(.*\) if \w+ is None'),
    # A general least-squares solver (the alignment's reweighted fit on rotations is not one).
    'least-squares solvers': (
        'lumpbeam_ros/core/ident/optimize.py',
        r'def \w*(gauss_newton|levenberg|marquardt)\w*\(',
    ),
    # A Gauss-Newton step on the reprojection error of the board's corners.
    'reprojection fits': (
        'lumpbeam_ros/core/vision/reprojection.py',
        r'inverse @ \(j\.T @ r\)|solve\(jtj',
    ),
    # A walk over MCAP records: each record's opcode and length read before its content.
    'MCAP record walkers': ('lumpbeam_ros/core/bagio/reader.py', r'\.read1\(\)|_RECORD_HEADER'),
}


def twins(repo: Path) -> list[str]:
    """Places that do again what :data:`TWINS` gives one home (``concept: file:line``)."""
    found = []
    for concept, (home, pattern) in TWINS.items():
        for hit in _grep(repo, pattern, (home,)):
            found.append(f'{concept}: {hit}')
    return found


def main(argv: list[str]) -> int:
    """Prints the counts, each with the places that make it up."""
    repo = Path(argv[1]) if len(argv) > 1 else Path(__file__).resolve().parents[1]
    rows = {
        'interface names as literals outside lumpbeam_ros/base/interface.py': literal_uses(repo),
        'declare_parameter calls outside nodes/ros_parameters.py': _grep(
            repo, r'\.declare_parameters?\(', ('lumpbeam_ros/nodes/ros_parameters.py',)
        ),
        'tip-series types (classes with their own z column)': _grep(repo, r'^    z: np\.ndarray$'),
        'places decoding /tip_pose (the bag reader; nodes on live messages)': _grep(
            repo, r'pose_values\(', ('lumpbeam_ros/core/bagio/convert.py',)
        ),
        'node parameters whose literal default or bound is written in more than one place': (
            repeated_parameter_literals(repo)
        ),
        'node parameters declared but never read': unread_parameters(repo),
        'places to change to add an effect (besides its physics)': effect_places(repo),
        'lab modules imported by the core': lab_imports(repo),
        'readers of bags besides bagio/reader.py and its tested fast path': bag_readers(repo),
        'imports that run back up the floors or the core': imports_back_up(repo),
        'twins (a concept done again outside its one home)': twins(repo),
        'configuration types named against the rule (Config, Settings, Options, Parameters)': (
            config_type_names(repo)
        ),
    }
    for title, hits in rows.items():
        print(f'{title}: {len(hits)}')
        for hit in hits:
            print(f'  {hit}')
    tests = _load(repo / 'tools' / 'test_modules.py', 'test_modules')
    missing = [
        *tests.missing_tests(repo),  # type: ignore[attr-defined]
        *tests.missing_tests(repo, tests.LAB),  # type: ignore[attr-defined]
    ]
    print(f'core modules without a test module: {len(missing)} (python tools/test_modules.py)')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
