"""The beam as markers: the chain's joints (B.17), the scene's markers, the marker rate."""

import math

import numpy as np
import pytest

from lumpbeam_ros.core.viz.markers import (
    BEAM_WIDTH_M,
    BOARD_THICKNESS_M,
    LOAD_HOOK_M,
    NS_BEAM,
    NS_BOARD,
    NS_JOINTS,
    NS_LINK,
    NS_LOAD,
    NS_MEASURED,
    NS_PREDICTED,
    STEEL_DENSITY_KG_M3,
    TIP_DIAMETER_M,
    Action,
    BeamScene,
    Shape,
    TipPoint,
    joint_positions,
    lifetime_for_rate,
    load_cube_side_m,
    marker_sample_indices,
    scene_markers,
)

from .helpers import BOARD, SEGMENT_M, full_scene


@pytest.mark.parametrize(
    'phi',
    [
        np.zeros(5),
        np.full(3, math.pi / 2),
        np.linspace(0.0, 0.05, 10),
        np.array([0.1, -0.2, 0.3]),
        np.array([]),
    ],
    ids=['straight', 'hanging', 'sagging', 'wavy', 'no-segment'],
)
def test_joints_follow_the_segment_angles(phi):
    points = joint_positions(SEGMENT_M, phi)
    assert points.shape == (phi.size + 1, 3)
    np.testing.assert_array_equal(points[0], [0.0, 0.0, 0.0])  # joint 1 at the clamp
    # B.17 in the complex plane: x + i z steps by L_s e^{-i phi}.
    chain = np.concatenate([[0.0], np.cumsum(SEGMENT_M * np.exp(-1j * phi))])
    np.testing.assert_allclose(points[:, 0], chain.real, atol=1e-15)
    np.testing.assert_allclose(points[:, 2], chain.imag, atol=1e-15)
    assert np.all(points[:, 1] == 0.0)
    np.testing.assert_allclose(np.linalg.norm(np.diff(points, axis=0), axis=1), SEGMENT_M)


def test_a_downward_angle_lowers_the_tip():
    tip = joint_positions(1.0, np.full(4, 0.01))[-1]
    assert tip[2] < 0.0 and tip[0] == pytest.approx(4 * math.cos(0.01))


@pytest.mark.parametrize('load_kg', [0.0, 1.0, 4.5, 20.0])
def test_the_load_cube_weighs_the_load(load_kg):
    side = load_cube_side_m(load_kg)
    assert side**3 * STEEL_DENSITY_KG_M3 == pytest.approx(load_kg, abs=1e-12)


def test_a_full_scene_has_one_marker_per_object():
    scene = full_scene()
    markers = scene_markers(scene, 0.1)
    assert [m.namespace for m in markers] == [
        NS_BEAM,
        NS_MEASURED,
        NS_PREDICTED,
        NS_LOAD,
        NS_BOARD,
    ]
    assert all(m.marker_id == 0 and m.action == Action.ADD for m in markers)
    assert all(m.lifetime_s == 0.1 for m in markers)
    beam, measured, predicted, load, board = markers
    assert beam.shape == Shape.LINE_STRIP and beam.scale[0] == BEAM_WIDTH_M
    np.testing.assert_array_equal(beam.points, joint_positions(SEGMENT_M, scene.phi))
    assert measured.shape == predicted.shape == Shape.SPHERE
    assert measured.position == (2.298, 0.0, -0.0351)
    assert predicted.position == (2.299, 0.0, -0.0349)
    assert measured.scale == (TIP_DIAMETER_M,) * 3
    # The load hangs below the model's tip: hook, then half the cube.
    side = load_cube_side_m(4.5)
    assert load.shape == Shape.CUBE and load.scale == (side, side, side)
    assert load.position == pytest.approx((2.299, 0.0, -0.0349 - LOAD_HOOK_M - side / 2))
    assert board.position == BOARD.center and board.orientation == BOARD.orientation
    assert board.scale == (BOARD.width_m, BOARD.height_m, BOARD_THICKNESS_M)


def _load_marker(scene):
    return next(m for m in scene_markers(scene, 0.2) if m.namespace == NS_LOAD)


@pytest.mark.parametrize(
    ('scene', 'hook'),
    [
        # No predicted tip: the chain's free end carries the load.
        (BeamScene(SEGMENT_M, phi=np.zeros(10), load_kg=2.0), (2.3, 0.0)),
        # No model at all: below the measured tip.
        (BeamScene(SEGMENT_M, measured=TipPoint(2.2, -0.04), load_kg=2.0), (2.2, -0.04)),
    ],
    ids=['chain-end', 'measured-tip'],
)
def test_the_load_hangs_from_the_model_else_the_measurement(scene, hook):
    load = _load_marker(scene)
    side = load_cube_side_m(2.0)
    assert load.action == Action.ADD
    assert load.position == pytest.approx((hook[0], 0.0, hook[1] - LOAD_HOOK_M - side / 2))


@pytest.mark.parametrize(
    'scene',
    [
        full_scene(load_kg=0.0),
        BeamScene(SEGMENT_M, load_kg=4.5),  # nothing to hang it from
        BeamScene(SEGMENT_M, measured=TipPoint(math.nan, -0.04), load_kg=4.5),
        BeamScene(SEGMENT_M, predicted=TipPoint(2.3, math.inf), load_kg=4.5),
    ],
    ids=['released', 'no-tip', 'nan-measured', 'inf-predicted'],
)
def test_without_a_load_or_a_hook_the_load_is_deleted(scene):
    load = _load_marker(scene)
    assert (load.action, load.shape, load.lifetime_s) == (Action.DELETE, Shape.CUBE, 0.0)


@pytest.mark.parametrize(
    ('tip', 'finite'),
    [
        (TipPoint(2.3, -0.05), True),
        (TipPoint(math.nan, 0.0), False),
        (TipPoint(0.0, -math.inf), False),
    ],
    ids=['finite', 'nan-x', 'inf-z'],
)
def test_a_tip_that_is_not_finite_is_left_out(tip, finite):
    assert tip.is_finite() is finite
    names = [m.namespace for m in scene_markers(BeamScene(SEGMENT_M, measured=tip), 0.1)]
    assert names == ([NS_MEASURED, NS_LOAD] if finite else [NS_LOAD])


@pytest.mark.parametrize('bad', [math.nan, math.inf, -math.inf])
def test_angles_that_are_not_finite_are_refused(bad):
    scene = BeamScene(SEGMENT_M, phi=np.array([0.0, bad, 0.01]))
    with pytest.raises(ValueError, match='segment angles must be finite'):
        scene_markers(scene, 0.1)


@pytest.mark.parametrize(
    ('t', 'rate', 'expected'),
    [
        (np.arange(36) / 180.0, 30.0, list(range(0, 36, 6))),
        (np.arange(36) / 180.0, 180.0, list(range(36))),
        (np.arange(36) / 180.0, 1000.0, list(range(36))),
        (np.arange(36) / 180.0, 1.0, [0]),
        (np.array([0.0, 0.01, 0.05, 0.12, 0.13, 0.31]), 10.0, [0, 3, 5]),
        (10.0 + np.array([0.0, 0.099, 0.1, 0.2]), 10.0, [0, 2, 3]),
        (np.array([]), 30.0, []),
    ],
    ids=['180-to-30', 'same-rate', 'faster', 'slower-than-record', 'gaps', 'offset', 'empty'],
)
def test_marker_samples_take_the_first_of_each_period(t, rate, expected):
    indices = marker_sample_indices(t, rate)
    assert indices.tolist() == expected
    assert indices.dtype.kind == 'i'


@pytest.mark.parametrize('rate', [0.0, -30.0, math.nan, math.inf])
def test_a_marker_rate_that_is_not_positive_is_refused(rate):
    with pytest.raises(ValueError, match='marker rate must be a positive number of Hz'):
        marker_sample_indices(np.arange(3.0), rate)


@pytest.mark.parametrize(('rate', 'lifetime'), [(30.0, 0.1), (10.0, 0.3), (1.0, 3.0)])
def test_the_lifetime_spans_three_periods(rate, lifetime):
    assert lifetime_for_rate(rate) == pytest.approx(lifetime)


def test_an_arm_is_drawn_link_by_link_with_its_joints():
    lengths = np.array([0.5, 0.5, 0.3, 0.3, 0.3])
    phi = np.array([0.1, 0.2, -0.4, -0.3, -0.2])
    scene = BeamScene(lengths, phi=phi, link_starts=(0, 2))
    markers = scene_markers(scene, 0.1)
    assert not [m for m in markers if m.namespace == NS_BEAM]
    links = [m for m in markers if m.namespace == NS_LINK]
    points = joint_positions(lengths, phi)
    assert [m.marker_id for m in links] == [0, 1]
    assert all(m.shape == Shape.LINE_STRIP for m in links)
    np.testing.assert_array_equal(links[0].points, points[:3])  # joint 1 to joint 2
    np.testing.assert_array_equal(links[1].points, points[2:])  # joint 2 to the free end
    joints = next(m for m in markers if m.namespace == NS_JOINTS)
    assert joints.shape == Shape.SPHERE_LIST
    np.testing.assert_array_equal(joints.points, points[[0, 2]])
    # Each segment its own length: the free end is the sum of the steps (B.17).
    assert points[-1, 0] == pytest.approx(np.sum(lengths * np.cos(phi)))
    assert points[-1, 2] == pytest.approx(-np.sum(lengths * np.sin(phi)))
