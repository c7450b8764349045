"""Figure files checked with Pillow, a decoder independent of matplotlib's PNG writer."""

from __future__ import annotations

import io
from pathlib import Path

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
