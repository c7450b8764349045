"""One self-contained HTML page: inline CSS, figures as base64 PNG, no script, no network.

A page opened from a laptop, a mail attachment or a CI artifact shows everything: nothing is
fetched (even the favicon is an empty data URI, so a browser logs no failed request).
"""

from __future__ import annotations

import base64
import html
import math
import os
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from lumpbeam_ros.base.errors import LumpbeamError

_STYLE = """
body { font-family: sans-serif; margin: 2em auto; max-width: 70em; color: #222; }
h1 { font-size: 1.5em; } h2 { font-size: 1.2em; margin-top: 1.8em; }
table { border-collapse: collapse; margin: 0.5em 0; }
td, th { border: 1px solid #ccc; padding: 0.2em 0.6em; text-align: right; }
th { background: #f0f0f0; } td.name, th.name { text-align: left; }
img { max-width: 100%; border: 1px solid #eee; }
p.note { color: #555; }
"""

Cell = str | float | int | None

#: Below this magnitude a float's integer part is exact (2**53 ~ 9.0e15): it is printed whole.
_WHOLE_BELOW = 1e15


def format_value(value: Cell, digits: int = 5) -> str:
    """A table cell as text: numbers to ``digits`` significant digits, NaN and None as n/a.

    A float with more integer digits than ``digits`` (an epoch stamp, 1.7e9 s) keeps all of
    them and up to ``digits`` decimals, trailing zeros dropped: rounded to ``digits``
    significant digits it would read ``1.7e+09``, years rounded away.

    Args:
        value: The cell.
        digits: Significant digits of a float.

    Returns:
        The text.
    """
    if value is None:
        return 'n/a'
    if isinstance(value, bool):
        return str(value)
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            return 'n/a'
        if 10.0**digits <= abs(value) < _WHOLE_BELOW:
            return f'{value:.{digits}f}'.rstrip('0').rstrip('.')
        return f'{value:.{digits}g}'
    return str(value)


@dataclass
class HtmlReport:
    """A report page assembled block by block, then written in one piece.

    Attributes:
        title: The page's title and first heading.
        blocks: HTML fragments, in order.
    """

    title: str
    blocks: list[str] = field(default_factory=list)

    def heading(self, text: str) -> None:
        """Adds a section heading."""
        self.blocks.append(f'<h2>{html.escape(text)}</h2>')

    def paragraph(self, text: str, note: bool = False) -> None:
        """Adds a paragraph of plain text (escaped)."""
        css = ' class="note"' if note else ''
        self.blocks.append(f'<p{css}>{html.escape(text)}</p>')

    def table(self, header: Sequence[str], rows: Iterable[Sequence[Cell]]) -> None:
        """Adds a table; the first column is left-aligned (names), the rest right-aligned.

        Args:
            header: Column titles.
            rows: Cells; floats are shown with 5 significant digits.
        """
        head = ''.join(
            f'<th{" class=name" if i == 0 else ""}>{html.escape(h)}</th>'
            for i, h in enumerate(header)
        )
        body = []
        for row in rows:
            cells = ''.join(
                f'<td{" class=name" if i == 0 else ""}>{html.escape(format_value(c))}</td>'
                for i, c in enumerate(row)
            )
            body.append(f'<tr>{cells}</tr>')
        self.blocks.append(f'<table><tr>{head}</tr>{"".join(body)}</table>')

    def png(self, data: bytes, alt: str) -> None:
        """Adds a PNG image, embedded as a base64 data URI.

        Raises:
            LumpbeamError: ``data`` is not a PNG.
        """
        if not data.startswith(b'\x89PNG\r\n\x1a\n'):
            raise LumpbeamError(f'figure {alt!r} is not a PNG image')
        encoded = base64.b64encode(data).decode('ascii')
        self.blocks.append(
            f'<figure><img alt="{html.escape(alt)}" src="data:image/png;base64,{encoded}">'
            f'<figcaption>{html.escape(alt)}</figcaption></figure>'
        )

    def png_files(self, paths: Iterable[Path]) -> None:
        """Embeds PNG files written by the product's plot functions."""
        for path in paths:
            self.png(Path(path).read_bytes(), Path(path).stem.replace('_', ' '))

    def render(self) -> str:
        """The whole page."""
        return (
            '<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
            f'<title>{html.escape(self.title)}</title>'
            '<link rel="icon" href="data:,">'
            f'<style>{_STYLE}</style></head><body>'
            f'<h1>{html.escape(self.title)}</h1>\n' + '\n'.join(self.blocks) + '\n</body></html>\n'
        )

    def write(self, path: str | Path) -> Path:
        """Writes the page atomically (a reader never sees half a page).

        Args:
            path: The ``.html`` file; its folder is created when missing.

        Returns:
            The path written.

        Raises:
            LumpbeamError: The path does not end in ``.html``/``.htm`` or cannot be written.
        """
        path = Path(path)
        if path.suffix.lower() not in ('.html', '.htm'):
            raise LumpbeamError(f'--report {path}: the report is an HTML file (FILE.html)')
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            tmp = path.with_name(f'.{path.name}.{os.getpid()}.tmp')
            tmp.write_text(self.render(), encoding='utf-8')
            os.replace(tmp, path)
        except OSError as exc:
            raise LumpbeamError(f'cannot write the report {path}: {exc.strerror or exc}') from None
        return path


def figure_png(fig: object, dpi: int = 110) -> bytes:
    """A matplotlib figure as PNG bytes; the figure is closed.

    Args:
        fig: A ``matplotlib.figure.Figure``.
        dpi: Resolution.

    Returns:
        The PNG file's bytes.
    """
    import io

    import matplotlib.pyplot as plt

    buffer = io.BytesIO()
    try:
        fig.tight_layout()  # type: ignore[attr-defined]
        fig.savefig(buffer, format='png', dpi=dpi)  # type: ignore[attr-defined]
    finally:
        plt.close(fig)  # type: ignore[arg-type]
    return buffer.getvalue()


def estimate_rows(data: dict[str, object], keys: Iterable[str]) -> list[list[Cell]]:
    """Rows ``[key, value, std]`` for the keys of a result's JSON that hold numbers.

    Args:
        data: A command's JSON dictionary.
        keys: Which keys, in order; a key's ``_std`` (when present) fills the third column.

    Returns:
        The rows.
    """
    rows: list[list[Cell]] = []
    for key in keys:
        value = data.get(key)
        std = data.get(f'{key}_std')
        rows.append([key, as_cell(value), as_cell(std)])
    return rows


def as_cell(value: object) -> Cell:
    """A JSON value as a table cell: numbers and text as they are, anything else as text."""
    if value is None or isinstance(value, str | float | int):
        return value
    return str(value)
