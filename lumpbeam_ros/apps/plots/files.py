"""Writing a drawn figure to a file, one way for every plot of the package."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

from lumpbeam_ros.base.errors import LumpbeamError

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def save_figure(
    figure: Figure, path: str | Path, *, dpi: int, what: str = '', **options: Any
) -> Path:
    """Writes a figure into a file, creating its folder; the caller closes the figure.

    Args:
        figure: The drawn figure.
        path: The image file (PNG, or any format matplotlib writes).
        dpi: Its resolution.
        what: Words before the path in the error message (``'the plot '``).
        **options: More of matplotlib's ``savefig`` options (``bbox_inches='tight'``).

    Returns:
        The path written.

    Raises:
        LumpbeamError: The folder or the file cannot be written (one line).
    """
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        figure.savefig(path, dpi=dpi, **options)
    except OSError as exc:
        raise LumpbeamError(f'cannot write {what}{path}: {exc.strerror or exc}') from None
    return path
