"""Figure files checked with Pillow, a decoder independent of matplotlib's PNG writer."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
from PIL import Image

PNG_SIGNATURE = b'\x89PNG\r\n\x1a\n'


def png_size(data: bytes | Path) -> tuple[int, int]:
    """Decodes a PNG completely and returns its ``(width, height)`` in pixels.

    Args:
        data: The file's bytes, or its path.

    Returns:
        The size.

    Raises:
        AssertionError: Not a PNG, or it does not decode to the end.
    """
    raw = Path(data).read_bytes() if isinstance(data, Path) else bytes(data)
    assert raw.startswith(PNG_SIGNATURE), raw[:8]
    with Image.open(io.BytesIO(raw)) as image:
        assert image.format == 'PNG'
        image.load()  # inflates every row: a truncated file raises here
        return image.size


def color_rows(path: Path, rgb: tuple[int, int, int], tolerance: int = 12) -> np.ndarray:
    """The rows, as fractions of the height from the top, where a PNG has pixels of a colour.

    Args:
        path: The PNG file.
        rgb: The colour, 0..255 each.
        tolerance: Largest difference per channel (antialiasing blends the edges).

    Returns:
        One fraction in 0..1 per matching pixel.
    """
    with Image.open(path) as image:
        pixels = np.asarray(image.convert('RGB'), dtype=int)
    match = np.all(np.abs(pixels - np.array(rgb)) <= tolerance, axis=2)
    rows, _ = np.nonzero(match)
    return rows / pixels.shape[0]
