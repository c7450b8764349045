"""The checkerboard target: its corners in its own frame and its printed texture.

Board frame: origin at the centre of the squares, x along the rows of squares, y along the
columns (image-down when the board is seen upright), z into the wall (away from the camera).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Checkerboard:
    """A printed checkerboard with a white margin around its squares.

    Attributes:
        squares_x: Squares along the board's x axis (9 for an 8 x 6 inner-corner pattern).
        squares_y: Squares along the board's y axis.
        square_size_m: Edge length of one square, m.
        margin_squares: White border around the squares, in squares; OpenCV's detector
            needs a light quiet zone around the outer dark squares.
    """

    squares_x: int
    squares_y: int
    square_size_m: float
    margin_squares: float

    @property
    def pattern_size(self) -> tuple[int, int]:
        """Inner corners ``(per row, per column)``, the ``patternSize`` of OpenCV."""
        return (self.squares_x - 1, self.squares_y - 1)

    @property
    def n_corners(self) -> int:
        """Number of inner corners."""
        cols, rows = self.pattern_size
        return cols * rows

    @property
    def turn_swaps_colours(self) -> bool:
        """Whether the colours tell the board from itself turned by 180 degrees.

        A turn maps square ``(i, j)`` to ``(squares_x - 1 - i, squares_y - 1 - j)``, which
        has the other colour when ``squares_x + squares_y`` is odd (OpenCV's 10 x 7 squares
        of 9 x 6 corners); with an even sum (9 x 7 squares) the turned board looks the same.
        """
        return (self.squares_x + self.squares_y) % 2 == 1

    @property
    def corner_polarity(self) -> float:
        """Sign of corner 0's saddle in :func:`~lumpbeam_ros.core.vision.partial.board_polarity`.

        -1: the square on corner 0's ``(+x, +y)`` side is dark, as the corner square at
        ``(-x, -y)`` (:meth:`texture`, and OpenCV's labelling of its printed pattern).
        """
        return -1.0

    @property
    def outline_m(self) -> np.ndarray:
        """The printed sheet's four corners (4 x 3, board frame, margin included), m."""
        half_x = (self.squares_x / 2.0 + self.margin_squares) * self.square_size_m
        half_y = (self.squares_y / 2.0 + self.margin_squares) * self.square_size_m
        return np.array(
            [[-half_x, -half_y, 0.0], [half_x, -half_y, 0.0], [half_x, half_y, 0.0],
             [-half_x, half_y, 0.0]]
        )  # fmt: skip

    def object_points(self) -> np.ndarray:
        """Returns the inner corners in the board frame, row by row (N x 3, float64, m).

        The order is OpenCV's: index ``r * cols + c`` is corner ``c`` of row ``r``.
        """
        cols, rows = self.pattern_size
        u = (np.arange(cols) + 1.0 - self.squares_x / 2.0) * self.square_size_m
        v = (np.arange(rows) + 1.0 - self.squares_y / 2.0) * self.square_size_m
        uu, vv = np.meshgrid(u, v)
        return np.column_stack([uu.ravel(), vv.ravel(), np.zeros(uu.size)])

    def texture(
        self, texels_per_square: int, dark: float, light: float
    ) -> tuple[np.ndarray, np.ndarray]:
        """Renders the printed sheet as an image, one texel grid aligned with the squares.

        Args:
            texels_per_square: Texture resolution; square edges fall on texel boundaries.
            dark: Value of the dark squares.
            light: Value of the light squares and the margin.

        Returns:
            The texture (float32, rows along board y) and the 3x3 affine map from texel
            coordinates (pixel centres at integers, OpenCV's convention) to board-frame
            ``(x, y, 1)`` in metres.
        """
        n = int(texels_per_square)
        margin = int(round(self.margin_squares * n))
        squares = np.indices((self.squares_y, self.squares_x)).sum(axis=0) % 2
        # The corner square is dark, as on OpenCV's printed pattern.
        cells = np.where(squares == 0, dark, light).astype(np.float32)
        body = np.kron(cells, np.ones((n, n), dtype=np.float32))
        sheet = np.pad(body, margin, constant_values=light)
        scale = self.square_size_m / n
        offset_x = -(self.squares_x * n / 2.0 + margin) * scale
        offset_y = -(self.squares_y * n / 2.0 + margin) * scale
        # Texel i covers [i - 0.5, i + 0.5), so its left edge is board x = offset + i * scale.
        to_board = np.array(
            [[scale, 0.0, offset_x + 0.5 * scale], [0.0, scale, offset_y + 0.5 * scale],
             [0.0, 0.0, 1.0]]
        )  # fmt: skip
        return sheet, to_board
