"""The user docs: their examples run, and doc/interfaces.md names everything the code defines.

The names are taken from the code itself (topic strings, the JSON dictionaries the commands
write, the identification's fields, the effect table, the argument parsers), so a key, topic
or option added to the code without a line in doc/interfaces.md fails here, as does an item
the page still calls planned after the code has it.
"""

from __future__ import annotations

import argparse
import ast
import doctest
import importlib.util
import os
import re
import shutil
import subprocess
import sys
from dataclasses import fields
from functools import cache
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote

import pytest

from lumpbeam_lab.bench.bench_result import BenchResult
from lumpbeam_ros.apps.campaign.task import ID_COLUMNS
from lumpbeam_ros.apps.cli.analyze import CONTRACT_KEYS
from lumpbeam_ros.apps.cli.main import COMMANDS, build_parser
from lumpbeam_ros.core.diagnose.gap import Gap
from lumpbeam_ros.core.diagnose.signatures import Signatures
from lumpbeam_ros.core.ident.arm.link_fit import MeasuredMode
from lumpbeam_ros.core.ident.identification import Identification, Status
from lumpbeam_ros.core.model.parameters import EFFECT_PARAMETERS
from lumpbeam_ros.core.model.reproduce import Comparison, TableRow

ROOT = Path(__file__).resolve().parents[1]


def _docs_site():
    spec = importlib.util.spec_from_file_location('docs_site', ROOT / 'tools' / 'docs_site.py')
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


PACKAGE = ROOT / 'lumpbeam_ros'
DOCS = sorted((ROOT / 'doc').glob('*.md'))
INTERFACES = ROOT / 'doc' / 'interfaces.md'
TEXT = INTERFACES.read_text(encoding='utf-8')

#: The section titles code and docs point to; they must not change.
SECTIONS = (
    'Beam model',
    'Frames, units and time',
    'Topics',
    'Bags',
    'Command line',
    'Missing effects',
    'Configuration',
)

#: The effect names the interface reserves, implemented or not.
CONTRACT_EFFECTS = {
    'base_compliance': 'k_base_nm_per_rad',
    'coulomb_friction': 'torque_nm',
    'quadratic_drag': 'c_q',
    'added_mass': 'mass_kg',
    'sensor_latency': 'latency_s',
    'cubic_stiffness': 'k3_nm_per_rad3',
    'sensor_scale': 'scale',
    'mount_tilt': 'tilt_rad',
}

TOPIC_NAME = re.compile(r'/[a-z][a-z0-9_]*(?:/[a-z][a-z0-9_]*)*')
#: Paths of the operating system that look like topic names.
SYSTEM_PATHS = re.compile(r'/(?:proc|sys|dev|etc|tmp)(?:/.*)?')
PLANNED = re.compile(r'`([^`]+)` \(planned\)')


def _parse(relative: str) -> ast.Module:
    return ast.parse((PACKAGE / relative).read_text(encoding='utf-8'))


def _function(relative: str, qualname: str) -> ast.AST:
    """The definition ``qualname`` (``'Class.method'`` or ``'function'``) in a module."""
    scope: ast.AST = _parse(relative)
    for part in qualname.split('.'):
        scope = next(
            node
            for node in ast.iter_child_nodes(scope)
            if isinstance(node, ast.FunctionDef | ast.ClassDef) and node.name == part
        )
    return scope


def _string(node: ast.AST | None) -> str | None:
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    return None


def dict_keys(relative: str, qualname: str) -> set[str]:
    """String keys a function puts into dictionaries: literals and ``d['key'] = ...``."""
    keys: set[str] = set()
    for node in ast.walk(_function(relative, qualname)):
        if isinstance(node, ast.Dict):
            keys |= {k for k in map(_string, node.keys) if k is not None}
        elif isinstance(node, ast.Subscript) and isinstance(node.ctx, ast.Store):
            key = _string(node.slice)
            if key is not None:
                keys.add(key)
    return keys


def pair_keys(relative: str, qualname: str) -> set[str]:
    """First items of the literal ``('key', value)`` pairs in a function."""
    return {
        key
        for node in ast.walk(_function(relative, qualname))
        if isinstance(node, ast.Tuple) and len(node.elts) == 2
        for key in [_string(node.elts[0])]
        if key is not None
    }


def field_names(cls: type) -> set[str]:
    return {f.name for f in fields(cls)}


@cache
def code_topics() -> frozenset[str]:
    """Every string constant in the package that is a whole topic name."""
    topics = set()
    for path in PACKAGE.rglob('*.py'):
        for node in ast.walk(ast.parse(path.read_text(encoding='utf-8'))):
            value = _string(node)
            if value is not None and TOPIC_NAME.fullmatch(value):
                if not SYSTEM_PATHS.fullmatch(value):
                    topics.add(value)
    return frozenset(topics)


@cache
def json_keys() -> dict[str, set[str]]:
    """The keys each output of the product writes, by where they come from."""
    identification = set(Identification(Status.ERROR, '').as_dict())
    return {
        'reproduce': dict_keys('apps/cli/reproduce.py', 'result_json')
        | field_names(TableRow)
        | field_names(Comparison)
        | dict_keys('core/model/reproduce.py', 'paper_frequencies')
        | dict_keys('core/model/reproduce.py', 'static_test'),
        'analyze': set(CONTRACT_KEYS)
        | {f'{key}_std' for key in CONTRACT_KEYS}
        | {'release_time_s', 'static_deflection_m'}
        | identification,
        '/beam_params': (identification - {'status', 'message'})
        | pair_keys('nodes/identifier_node.py', 'IdentifierNode.diagnostics'),
        '/diagnostics': dict_keys('nodes/camera_node.py', 'CameraNode.diagnostic_status'),
        'diagnose': dict_keys('core/diagnose/workflow.py', 'Diagnosis.as_dict')
        | dict_keys('core/diagnose/workflow.py', '_score_details')
        | field_names(Gap)
        | field_names(Signatures),
        'compare': dict_keys('core/compare/comparison.py', 'Comparison.as_dict'),
        'track': dict_keys('apps/cli/track.py', 'run'),
        'bench': dict_keys('apps/cli/bench.py', 'run') | field_names(BenchResult),
        'demo': dict_keys('apps/demo/summary.py', 'summarize'),
        'campaign': set(ID_COLUMNS),
        'fit-links': dict_keys('core/ident/arm/link_fit.py', 'LinkEstimate.as_dict')
        | dict_keys('core/ident/arm/link_fit.py', 'LinkFit.as_json')
        | dict_keys('apps/cli/fit_links.py', 'run_fit_links')
        | {f.name for f in fields(MeasuredMode)},
        'shape': dict_keys('apps/cli/shape.py', 'run')
        | dict_keys('core/shaping/vibration.py', 'vibration_summary')
        | dict_keys('core/shaping/impulses.py', 'Impulses.as_list'),
    }


def subparsers() -> dict[str, argparse.ArgumentParser]:
    action = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    return dict(action.choices)


def section(title: str) -> str:
    """The text of one ``##``/``###`` section, up to the next heading of its level or above."""
    level = title.split(' ')[0]
    match = re.search(rf'^{re.escape(title)}$(.*?)(?=^#{{1,{len(level)}}} |\Z)', TEXT, re.M | re.S)
    assert match, f'doc/interfaces.md has no section {title!r}'
    return match.group(1)


@pytest.mark.parametrize('path', DOCS, ids=lambda p: p.name)
def test_doc_examples_run(path):
    result = doctest.testfile(
        str(path),
        module_relative=False,
        optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE,
        encoding='utf-8',
    )
    assert result.failed == 0, f'{result.failed} failing example(s) in {path.name}; see above'


def test_interfaces_has_runnable_examples():
    examples = doctest.DocTestParser().get_examples(TEXT)
    assert len(examples) >= 20


@pytest.mark.parametrize('title', SECTIONS)
def test_stable_section_titles(title):
    assert re.search(rf'^## {re.escape(title)}$', TEXT, re.M)


def test_self_contained():
    # A clone of the product has only its own docs: no outside contract file to point to.
    assert not re.search(r'SPEC|\.\./shared|shared/', TEXT)


def test_every_topic_of_the_code_is_listed():
    missing = sorted(t for t in code_topics() if f'`{t}`' not in TEXT)
    assert not missing, f'add these topics to doc/interfaces.md "Topics": {missing}'


@pytest.mark.parametrize('output', sorted(json_keys()))
def test_every_output_key_is_listed(output):
    keys = json_keys()[output]
    assert keys, f'no keys found for {output}: has the code moved?'
    missing = sorted(k for k in keys if f'`{k}`' not in TEXT and not _inline_listed(k))
    assert not missing, f'add these {output} keys to doc/interfaces.md: {missing}'


def _inline_listed(key: str) -> bool:
    """Keys inside a braced list, e.g. `{n_s, uniform_m, loaded_m, end_load_m}`."""
    return any(
        re.search(rf'(?<![\w]){re.escape(key)}(?![\w])', group)
        for group in re.findall(r'`\{([^`]*)\}`', TEXT)
    )


def test_every_command_and_option_is_listed():
    parsers = subparsers()
    headings = re.findall(r'^### lumpbeam (\w+)( \(planned\))?$', TEXT, re.M)
    for name, planned in headings:
        assert (name in parsers) != bool(planned), (
            f'doc/interfaces.md "### lumpbeam {name}": planned or not, as the code has it'
        )
    for name, parser in parsers.items():
        text = section(f'### lumpbeam {name}')
        assert text.strip(), f'doc/interfaces.md has no "### lumpbeam {name}" section'
        for action in parser._actions:
            for option in action.option_strings:
                if option in ('-h', '--help'):
                    continue
                assert re.search(rf'`{re.escape(option)}[` ]', text), (
                    f'doc/interfaces.md "### lumpbeam {name}" does not list {option}'
                )


def test_planned_items_are_not_in_the_code_yet():
    # Nothing may be marked planned once the code has it (an empty list passes: all is built).
    planned = PLANNED.findall(TEXT)
    options = {
        option
        for parser in subparsers().values()
        for a in parser._actions
        for option in a.option_strings
    }
    topics = code_topics()
    done = []
    for item in planned:
        if item.startswith('lumpbeam '):
            done += [item] if item.split()[1] in COMMANDS else []
        elif item.startswith('--'):
            done += [item] if item in options else []
        elif item.startswith('/'):
            done += [item] if item in topics else []
        elif item in CONTRACT_EFFECTS:
            done += [item] if item in EFFECT_PARAMETERS else []
        else:
            pytest.fail(
                f'doc/interfaces.md marks {item!r} planned: not a command, option, '
                'topic or effect this test knows'
            )
    assert not done, f'the code has these; drop "(planned)" in doc/interfaces.md: {done}'


def test_missing_effects_table():
    text = section('## Missing effects')
    rows = dict(re.findall(r'^\| `(\w+)`(?: \(planned\))? \| `(\w+)` \|', text, re.M))
    # The contract's effects, and any more the library holds.
    assert CONTRACT_EFFECTS.items() <= rows.items()
    assert rows.items() - CONTRACT_EFFECTS.items() <= EFFECT_PARAMETERS.items()
    assert set(EFFECT_PARAMETERS.items()) <= set(rows.items())
    for name in rows:
        implemented = re.search(rf'^\| `{name}` \|.*\| yes \|$', text, re.M) is not None
        assert implemented == (name in EFFECT_PARAMETERS), (
            f'doc/interfaces.md "Missing effects": {name} is '
            f'{"" if name in EFFECT_PARAMETERS else "not "}in the model'
        )


# --- The README and the documentation site -------------------------------------------------

README = ROOT / 'README.md'
#: The README is a quick start; the evidence and the details live under doc/.
README_MAX_LINES = 250
#: A command line in the README's code blocks: ``lumpbeam COMMAND ...``.
README_COMMAND = re.compile(r'^(?:\$ )?lumpbeam (\w+)(.*)$', re.M)


def readme_code() -> str:
    """The README's fenced code blocks, one after the other."""
    return '\n'.join(
        re.findall(r'^```\w*\n(.*?)^```', README.read_text(encoding='utf-8'), re.M | re.S)
    )


def test_readme_is_a_quick_start():
    lines = README.read_text(encoding='utf-8').splitlines()
    assert len(lines) <= README_MAX_LINES, (
        f'README.md has {len(lines)} lines: move the details into a page under doc/'
    )


def test_readme_commands_exist():
    # Each `lumpbeam COMMAND --option` the README shows is a real subcommand and option.
    parsers = subparsers()
    shown = README_COMMAND.findall(readme_code())
    assert {'track', 'analyze', 'diagnose', 'compare', 'campaign', 'view'} <= {c for c, _ in shown}
    for command, rest in shown:
        assert command in parsers, f'README.md shows `lumpbeam {command}`: no such command'
        options = {o for a in parsers[command]._actions for o in a.option_strings}
        for option in re.findall(r'(?<!\S)(--[\w-]+)', rest.split('#')[0]):
            assert option in options, f'README.md: `lumpbeam {command}` has no {option}'


def test_readme_links_into_doc_resolve():
    # On a Git host the README links straight to the pages (the site's home page rewrites them).
    text = README.read_text(encoding='utf-8')
    for target in re.findall(r'\]\(([^)#]+)', text):
        assert not re.match(r'\w+://', target), f'README.md links outside: {target}'
        assert (ROOT / target).is_file(), f'README.md links to a missing file: {target}'


@pytest.fixture(scope='module')
def site(tmp_path_factory) -> Path:
    """The documentation site, built as ``make docs`` builds it, with warnings as errors."""
    out = tmp_path_factory.mktemp('site')
    result = subprocess.run(
        [sys.executable, '-m', 'mkdocs', 'build', '--strict', '--quiet', '--site-dir', str(out)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert result.returncode == 0, f'mkdocs build --strict failed:\n{result.stdout}{result.stderr}'
    return out


class _Links(HTMLParser):
    """The ids a page defines and the local links (href, src) it makes."""

    def __init__(self) -> None:
        super().__init__()
        self.ids: set[str] = set()
        self.links: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        for name, value in attrs:
            if value is None:
                continue
            if name in ('id', 'name'):
                self.ids.add(value)
            elif name in ('href', 'src') and not re.match(r'[a-z][a-z0-9+.-]*:|//', value):
                self.links.append(value)


def _parse_pages(site: Path) -> dict[Path, _Links]:
    pages = {}
    for path in sorted(site.rglob('*.html')):
        parser = _Links()
        parser.feed(path.read_text(encoding='utf-8'))
        pages[path] = parser
    return pages


def broken_links(site: Path) -> list[str]:
    """Every local link of the built site whose file or anchor does not exist."""
    pages = _parse_pages(site)
    broken = []
    for page, parsed in pages.items():
        for link in parsed.links:
            address, _, anchor = unquote(link).partition('#')
            if address.startswith('/'):
                target = site / address.lstrip('/')
            else:
                target = page.parent / address if address else page
            target = Path(os.path.normpath(target))
            if target.is_dir():
                target = target / 'index.html'
            where = f'{page.relative_to(site)}: {link}'
            if not target.is_file():
                broken.append(f'{where} (no file)')
            elif anchor and target in pages and anchor not in pages[target].ids:
                broken.append(f'{where} (no anchor)')
    return broken


def test_site_links_resolve(site):
    assert (site / 'index.html').is_file()
    assert not broken_links(site)


def test_the_link_check_finds_a_broken_link(site, tmp_path):
    copy = tmp_path / 'site'
    shutil.copytree(site, copy)
    page = copy / 'guide' / 'index.html'
    page.write_text(
        page.read_text(encoding='utf-8') + '<a href="../interfaces/#no-such-heading">x</a>'
        '<a href="../no-such-page/">y</a>',
        encoding='utf-8',
    )
    assert broken_links(copy) == [
        'guide/index.html: ../interfaces/#no-such-heading (no anchor)',
        'guide/index.html: ../no-such-page/ (no file)',
    ]


def test_every_core_package_has_an_api_page(site):
    # The pages are generated from tools/test_modules.py's core list (tools/docs_site.py).
    names = _docs_site().core_packages()
    assert {'base', 'core.model', 'core.ident', 'nodes.params', 'apps.plots'} <= set(names)
    for name in names:
        page = site / 'api' / name / 'index.html'
        assert page.is_file(), f'no API page for lumpbeam_ros.{name}'
        assert f'id="lumpbeam_ros.{name}' in page.read_text(encoding='utf-8')


@pytest.mark.parametrize('name', ['bench', 'camera', 'top_level'])
def test_the_lab_has_its_api_pages(site, name):
    page = site / 'api' / 'lab' / name / 'index.html'
    assert page.is_file(), f'no API page for the lab: {name}'
    anchor = 'lumpbeam_lab.mujoco_arm' if name == 'top_level' else f'lumpbeam_lab.{name}'
    assert f'id="{anchor}' in page.read_text(encoding='utf-8')


def test_every_doc_page_is_on_the_site(site):
    for path in DOCS:
        assert (site / path.stem / 'index.html').is_file(), f'doc/{path.name} is not on the site'
