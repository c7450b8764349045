"""Marker scenes for the viz tests, and marker comparison across a round trip."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pytest

from lumpbeam_ros.core.viz.markers import BeamScene, BoardPlacement, MarkerSpec, TipPoint

#: ``L_s`` of the scenes, m.
SEGMENT_M = 0.23
#: A board placement (a quarter turn about z), not read from any config.
BOARD = BoardPlacement(
    (1.2, 0.8, -0.1), (0.0, 0.0, 0.7071067811865476, 0.7071067811865476), 0.66, 0.54
)


def full_scene(load_kg: float = 4.5) -> BeamScene:
    """Ten segments bent down evenly, both tips, the load and the board."""
    return BeamScene(
        SEGMENT_M,
        phi=np.linspace(0.0, 0.03, 10),
        measured=TipPoint(2.298, -0.0351),
        predicted=TipPoint(2.299, -0.0349),
        load_kg=load_kg,
        board=BOARD,
    )


def assert_same_markers(got: Sequence[MarkerSpec], expected: Sequence[MarkerSpec]) -> None:
    """Field by field; the colour is float32 in the message, every other number float64."""
    assert len(got) == len(expected)
    for a, b in zip(got, expected, strict=True):
        assert (a.namespace, a.marker_id, a.shape, a.action) == (
            b.namespace,
            b.marker_id,
            b.shape,
            b.action,
        )
        assert a.position == b.position and a.orientation == b.orientation
        assert a.scale == b.scale and a.lifetime_s == pytest.approx(b.lifetime_s, abs=1e-9)
        assert a.color == pytest.approx(b.color, rel=1e-7)
        np.testing.assert_array_equal(a.points, b.points)
        assert a.points.shape == (len(b.points), 3)
