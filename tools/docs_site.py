"""MkDocs hooks: the README is the site's home page; every core and lab package an API page.

Both are derived, never written twice. The home page is README.md with its links into
``doc/`` made relative to the site (and the pages' links back to ``../README.md`` pointed at
it), so the same Markdown reads right on a Git host and on the site. The API pages follow
the ROS-free parts that ``tools/test_modules.py`` lists, each package's page built from its
``__all__``: a new core package gets its page without an edit here. The lab
(``lumpbeam_lab``: benchmarks, validation, peers) gets a page per subpackage and one for its
top-level modules, under their own heading.
"""

from __future__ import annotations

import ast
import importlib.util
import re
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from mkdocs.config.defaults import MkDocsConfig
from mkdocs.structure.files import File, Files
from mkdocs.structure.pages import Page

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = 'lumpbeam_ros'
LAB = 'lumpbeam_lab'
HOME = 'index.md'
API_SECTION = 'API reference'

#: The README's links into doc/, the site's own folder.
_README_DOC_LINK = re.compile(r'\]\(doc/')
#: A page's link to the README, one folder up from doc/.
_PAGE_README_LINK = re.compile(r'\]\(\.\./README\.md')


def _load_tool() -> Any:
    path = ROOT / 'tools' / 'test_modules.py'
    spec = importlib.util.spec_from_file_location('test_modules_tool', path)
    if spec is None or spec.loader is None:
        raise RuntimeError(f'cannot load {path}')
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def public_names(package: Path) -> list[str]:
    """A package's ``__all__``, read from its ``__init__.py`` without importing it."""
    tree = ast.parse((package / '__init__.py').read_text(encoding='utf-8'))
    for node in tree.body:
        if isinstance(node, ast.Assign | ast.AnnAssign):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            if any(isinstance(t, ast.Name) and t.id == '__all__' for t in targets):
                return [str(name) for name in ast.literal_eval(node.value)]  # type: ignore[arg-type]
    return []


def core_packages() -> tuple[str, ...]:
    """The documented parts, dotted under the package (one API page each).

    They are the ROS-free parts that ``tools/test_modules.py`` lists; a floor made of
    packages (``core``) gives one part per package, in the order of its ``__all__``.
    """
    parts = []
    for entry in _load_tool().CORE_PACKAGES:
        dotted = entry.removesuffix('.py').replace('/', '.')
        folder = ROOT / PACKAGE / entry
        inside = (
            [p for p in public_names(folder) if (folder / p).is_dir()] if folder.is_dir() else []
        )
        parts += [f'{dotted}.{name}' for name in inside] if inside else [dotted]
    return tuple(parts)


def top_level_modules(package: str = PACKAGE) -> list[str]:
    """The modules at the top of a package, ``__init__`` aside."""
    return sorted(p.stem for p in (ROOT / package).glob('*.py') if p.stem != '__init__')


def lab_packages() -> list[str]:
    """The lab's subpackages (each folder of ``lumpbeam_lab`` with an ``__init__.py``)."""
    return sorted(p.parent.name for p in (ROOT / LAB).glob('*/__init__.py'))


def _package_pages(package: str, names: Iterable[str], folder: str) -> dict[str, str]:
    return {
        f'{folder}/{name}.md': f'# `{package}.{name}`\n\n::: {package}.{name}\n' for name in names
    }


def api_pages() -> dict[str, str]:
    """Site path -> Markdown of each API page: one per documented part of the product."""
    return _package_pages(PACKAGE, core_packages(), 'api')


def lab_api_pages() -> dict[str, str]:
    """Site path -> Markdown of the lab's API pages (``api/lab/``): its packages, its modules."""
    pages = _package_pages(LAB, lab_packages(), 'api/lab')
    modules = '\n'.join(f'::: {LAB}.{name}\n' for name in top_level_modules(LAB))
    pages['api/lab/top_level.md'] = f'# Top-level modules of `{LAB}`\n\n{modules}'
    return pages


def _listed(nav: Any) -> set[str]:
    """The page paths a navigation (nested lists and one-key mappings) names."""
    if isinstance(nav, str):
        return {nav}
    if isinstance(nav, dict):
        return set().union(*(_listed(value) for value in nav.values()))
    if isinstance(nav, list):
        return set().union(*(_listed(item) for item in nav))
    return set()


def on_config(config: MkDocsConfig, **_: Any) -> MkDocsConfig:
    """Completes the navigation ``mkdocs.yml`` starts.

    A page under ``doc/`` that it does not list comes next, titled by its first heading (a
    new page is on the site without an edit to ``mkdocs.yml``), then the API pages.
    """
    nav = list(config.nav or [])
    listed = _listed(nav)
    docs = Path(config.docs_dir)
    pages = (p.relative_to(docs).as_posix() for p in docs.rglob('*.md'))
    nav += sorted(page for page in pages if page not in listed | {HOME})
    product = [{Path(path).stem: path} for path in api_pages()]
    lab = [{Path(path).stem: path} for path in lab_api_pages()]
    nav.append({API_SECTION: [*product, {f'{LAB} (the lab)': lab}]})
    config.nav = nav
    return config


def on_files(files: Files, config: MkDocsConfig, **_: Any) -> Files:
    """Adds the generated pages: the home page from the README, and the API pages."""
    readme = (ROOT / 'README.md').read_text(encoding='utf-8')
    files.append(File.generated(config, HOME, content=_README_DOC_LINK.sub('](', readme)))
    for path, content in {**api_pages(), **lab_api_pages()}.items():
        files.append(File.generated(config, path, content=content))
    return files


def on_page_markdown(markdown: str, page: Page, **_: Any) -> str:
    """Points a page's links to ``../README.md`` at the home page."""
    return _PAGE_README_LINK.sub(f']({HOME}', markdown)
