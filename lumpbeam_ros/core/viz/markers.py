"""The beam as markers: the deflected chain, the tips, the hanging load and the checkerboard.

ROS-free: :func:`scene_markers` turns what is known at one instant (the model's segment
angles, the measured and predicted tip, the load, the board) into :class:`MarkerSpec`
descriptions in ``beam_base``, which :mod:`lumpbeam_ros.core.viz.marker_messages` writes as a
``visualization_msgs/msg/MarkerArray``. Every marker has a namespace and an id that stay the
same from one array to the next, so a viewer replaces the previous one instead of piling
them up, and a lifetime, so a stream that stops leaves nothing stale on screen; a marker
whose object is gone (the load after the drop) is deleted explicitly.

The chain's joints follow B.17: joint ``i + 1`` lies ``L_s`` from joint ``i`` along segment
``i``, whose absolute angle ``phi_i`` is positive when it points downward. An arm
(:mod:`lumpbeam_ros.core.model.arm`) is the same chain with a length per segment; it is drawn as
one line strip per link (namespace ``arm_link``, id = link index from 0, through every segment's
end) and its joints as spheres (``arm_joints``), in place of the beam's single strip.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from enum import IntEnum

import numpy as np

from lumpbeam_ros.base.interface import BASE_FRAME, BEAM_MARKERS

#: The topic and frame of the markers.
MARKERS_TOPIC = BEAM_MARKERS
FRAME_ID = BASE_FRAME

#: Namespaces, one per object; each object has id 0 in its namespace.
NS_BEAM = 'beam'
NS_MEASURED = 'tip_measured'
NS_PREDICTED = 'tip_predicted'
NS_LOAD = 'load'
NS_BOARD = 'board'
NS_LINK = 'arm_link'
NS_JOINTS = 'arm_joints'

#: A measured tip is drawn beside the model only this close in time to the model's stamp, s.
MEASURED_MAX_AGE_S = 0.5

#: Drawn sizes, m: the beam's line width, the tips' spheres, the board's thickness.
BEAM_WIDTH_M = 0.02
TIP_DIAMETER_M = 0.05
BOARD_THICKNESS_M = 0.005
#: The load is drawn as a steel cube (its volume says its mass) hanging this far below the tip.
STEEL_DENSITY_KG_M3 = 7850.0
LOAD_HOOK_M = 0.05

#: Colours, RGBA in 0..1.
BEAM_COLOR = (0.25, 0.45, 0.85, 1.0)
MEASURED_COLOR = (0.9, 0.2, 0.15, 1.0)
PREDICTED_COLOR = (0.1, 0.7, 0.3, 0.8)
LOAD_COLOR = (0.5, 0.5, 0.5, 1.0)
#: An arm's links alternate these colours, joint 1 outward; its joints are dark.
LINK_COLORS = (BEAM_COLOR, (0.95, 0.6, 0.1, 1.0))
JOINT_COLOR = (0.15, 0.15, 0.15, 1.0)
#: Drawn diameter of an arm's joints, m.
JOINT_DIAMETER_M = 0.04
BOARD_COLOR = (0.85, 0.85, 0.8, 0.6)

IDENTITY = (0.0, 0.0, 0.0, 1.0)


class Shape(IntEnum):
    """Marker types, with the values of ``visualization_msgs/msg/Marker``."""

    CUBE = 1
    SPHERE = 2
    LINE_STRIP = 4
    SPHERE_LIST = 7


class Action(IntEnum):
    """Marker actions, with the values of ``visualization_msgs/msg/Marker``."""

    ADD = 0
    DELETE = 2


@dataclass(frozen=True)
class MarkerSpec:
    """One marker, as ``visualization_msgs/msg/Marker`` holds it (frame ``beam_base``).

    Attributes:
        namespace: ``ns``: which object it is.
        marker_id: ``id`` within the namespace.
        shape: The marker type.
        action: Add (or replace) or delete.
        position: ``pose.position`` (x, y, z), m.
        orientation: ``pose.orientation`` (x, y, z, w).
        scale: ``scale`` (x, y, z), m; for a line strip x is the line width.
        color: RGBA, 0..1.
        points: The line strip's points (N x 3), m; empty for the other shapes.
        lifetime_s: How long a viewer keeps it without a newer one, s.
    """

    namespace: str
    marker_id: int
    shape: Shape
    action: Action = Action.ADD
    position: tuple[float, float, float] = (0.0, 0.0, 0.0)
    orientation: tuple[float, float, float, float] = IDENTITY
    scale: tuple[float, float, float] = (1.0, 1.0, 1.0)
    color: tuple[float, float, float, float] = (1.0, 1.0, 1.0, 1.0)
    points: np.ndarray = field(default_factory=lambda: np.empty((0, 3)))
    lifetime_s: float = 0.0


@dataclass(frozen=True)
class BoardPlacement:
    """The checkerboard sheet in ``beam_base``.

    Attributes:
        center: Its centre, m.
        orientation: The board frame's rotation (x, y, z, w): x along a row, y down it.
        width_m: Along the board's x, margin included, m.
        height_m: Along the board's y, margin included, m.
    """

    center: tuple[float, float, float]
    orientation: tuple[float, float, float, float]
    width_m: float
    height_m: float


@dataclass(frozen=True)
class TipPoint:
    """A planar tip position in ``beam_base`` (y = 0).

    Attributes:
        x: Along the undeformed beam, m.
        z: Vertical, m.
    """

    x: float
    z: float

    def is_finite(self) -> bool:
        """Whether both coordinates are finite numbers."""
        return math.isfinite(self.x) and math.isfinite(self.z)


@dataclass(frozen=True)
class BeamScene:
    """What is known at one instant; ``None`` leaves an object out.

    Attributes:
        segment_length_m: ``L_s``, m (an arm: one per segment).
        phi: The model's absolute segment angles (n_s,), rad; ``None``: no model shape.
        measured: The measured tip.
        predicted: The model's tip.
        load_kg: The mass hanging at the tip, kg (0: none; its marker is deleted).
        board: The checkerboard.
        link_starts: An arm's first segment of each link (empty: the clamped beam).
    """

    segment_length_m: float | np.ndarray
    phi: np.ndarray | None = None
    measured: TipPoint | None = None
    predicted: TipPoint | None = None
    load_kg: float = 0.0
    board: BoardPlacement | None = None
    link_starts: tuple[int, ...] = ()


def joint_positions(segment_length_m: float | np.ndarray, phi: np.ndarray) -> np.ndarray:
    """The chain's joints and its free end in ``beam_base`` (B.17).

    Args:
        segment_length_m: ``L_s``, m: one for all segments, or one per segment.
        phi: Absolute segment angles (n_s,), rad, positive pointing down.

    Returns:
        (n_s + 1) x 3 points: joint 1 at the clamp (the origin), ..., the free end last.
    """
    phi = np.asarray(phi, dtype=float)
    lengths = np.reshape(np.asarray(segment_length_m, dtype=float), (-1, 1))
    steps = lengths * np.column_stack([np.cos(phi), np.zeros_like(phi), -np.sin(phi)])
    return np.vstack([np.zeros((1, 3)), np.cumsum(steps, axis=0)])


def load_cube_side_m(load_kg: float) -> float:
    """Edge of the steel cube that weighs ``load_kg``, m."""
    return float((load_kg / STEEL_DENSITY_KG_M3) ** (1.0 / 3.0))


def _tip_marker(
    namespace: str, tip: TipPoint, color: tuple[float, float, float, float], lifetime_s: float
) -> MarkerSpec:
    return MarkerSpec(
        namespace,
        0,
        Shape.SPHERE,
        position=(tip.x, 0.0, tip.z),
        scale=(TIP_DIAMETER_M,) * 3,
        color=color,
        lifetime_s=lifetime_s,
    )


def _arm_markers(
    points: np.ndarray, link_starts: tuple[int, ...], lifetime_s: float
) -> list[MarkerSpec]:
    """An arm's links (a strip each, through its segments' ends) and its joints."""
    ends = (*link_starts[1:], points.shape[0] - 1)
    links = [
        MarkerSpec(
            NS_LINK,
            i,
            Shape.LINE_STRIP,
            scale=(BEAM_WIDTH_M, 0.0, 0.0),
            color=LINK_COLORS[i % len(LINK_COLORS)],
            points=points[start : end + 1],
            lifetime_s=lifetime_s,
        )
        for i, (start, end) in enumerate(zip(link_starts, ends, strict=True))
    ]
    joints = MarkerSpec(
        NS_JOINTS,
        0,
        Shape.SPHERE_LIST,
        scale=(JOINT_DIAMETER_M,) * 3,
        color=JOINT_COLOR,
        points=points[list(link_starts)],
        lifetime_s=lifetime_s,
    )
    return [*links, joints]


def scene_markers(scene: BeamScene, lifetime_s: float) -> list[MarkerSpec]:
    """The markers of one instant.

    Args:
        scene: What to draw.
        lifetime_s: Each added marker's lifetime, s (a few of the stream's periods).

    Returns:
        The beam (line strip through the joints; an arm: a strip per link and its joints),
        the measured and predicted tips (spheres),
        the load (a cube below the model's tip, else below the measured one; a delete when
        no load hangs) and the board (a thin cube), each present in the scene.

    Raises:
        ValueError: Angles that are not finite.
    """
    markers = []
    model_tip = scene.predicted
    if scene.phi is not None:
        if not np.all(np.isfinite(scene.phi)):
            raise ValueError('segment angles must be finite')
        points = joint_positions(scene.segment_length_m, scene.phi)
        if scene.link_starts:
            markers.extend(_arm_markers(points, scene.link_starts, lifetime_s))
        else:
            markers.append(
                MarkerSpec(
                    NS_BEAM,
                    0,
                    Shape.LINE_STRIP,
                    scale=(BEAM_WIDTH_M, 0.0, 0.0),
                    color=BEAM_COLOR,
                    points=points,
                    lifetime_s=lifetime_s,
                )
            )
        model_tip = model_tip or TipPoint(float(points[-1, 0]), float(points[-1, 2]))
    if scene.measured is not None and scene.measured.is_finite():
        markers.append(_tip_marker(NS_MEASURED, scene.measured, MEASURED_COLOR, lifetime_s))
    if scene.predicted is not None and scene.predicted.is_finite():
        markers.append(_tip_marker(NS_PREDICTED, scene.predicted, PREDICTED_COLOR, lifetime_s))
    hook = model_tip or scene.measured
    if scene.load_kg > 0.0 and hook is not None and hook.is_finite():
        side = load_cube_side_m(scene.load_kg)
        markers.append(
            MarkerSpec(
                NS_LOAD,
                0,
                Shape.CUBE,
                position=(hook.x, 0.0, hook.z - LOAD_HOOK_M - side / 2.0),
                scale=(side, side, side),
                color=LOAD_COLOR,
                lifetime_s=lifetime_s,
            )
        )
    else:
        markers.append(MarkerSpec(NS_LOAD, 0, Shape.CUBE, action=Action.DELETE))
    if scene.board is not None:
        board = scene.board
        markers.append(
            MarkerSpec(
                NS_BOARD,
                0,
                Shape.CUBE,
                position=board.center,
                orientation=board.orientation,
                scale=(board.width_m, board.height_m, BOARD_THICKNESS_M),
                color=BOARD_COLOR,
                lifetime_s=lifetime_s,
            )
        )
    return markers


def marker_sample_indices(t: np.ndarray, rate_hz: float) -> np.ndarray:
    """Which samples of a faster stream to draw at ``rate_hz``: the first of each period.

    Args:
        t: Sample times, s, increasing.
        rate_hz: The marker rate, Hz.

    Returns:
        Indices into ``t``, one per period ``1 / rate_hz`` that holds a sample.

    Raises:
        ValueError: A rate that is not a positive number.
    """
    if not math.isfinite(rate_hz) or rate_hz <= 0.0:
        raise ValueError(f'marker rate must be a positive number of Hz, got {rate_hz!r}')
    t = np.asarray(t, dtype=float)
    if t.size == 0:
        return np.empty(0, dtype=int)
    periods = np.floor((t - t[0]) * rate_hz + 1e-9).astype(np.int64)
    return np.flatnonzero(np.diff(periods, prepend=-1) > 0)


def lifetime_for_rate(rate_hz: float) -> float:
    """A marker lifetime for a stream at ``rate_hz``: a few periods, s."""
    return 3.0 / rate_hz
