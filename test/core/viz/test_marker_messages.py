"""Markers as ``visualization_msgs/MarkerArray``: through rclpy's serializer and back, in bags."""

import math

import numpy as np
import pytest

from lumpbeam_ros.base.errors import BagError
from lumpbeam_ros.core.bagio import BagReader, BagWriter
from lumpbeam_ros.core.bagio.typestore import deserialize, serialize
from lumpbeam_ros.core.viz.marker_messages import (
    MARKER_ARRAY_TYPE,
    marker_array,
    marker_message,
    marker_specs,
    read_marker_arrays,
    scene_cdr,
    write_scene,
    write_scene_ns,
)
from lumpbeam_ros.core.viz.markers import (
    FRAME_ID,
    MARKERS_TOPIC,
    Action,
    BeamScene,
    MarkerSpec,
    Shape,
    TipPoint,
    scene_markers,
)

from .helpers import SEGMENT_M, assert_same_markers, full_scene

serialization = pytest.importorskip('rclpy.serialization')
visualization_msgs = pytest.importorskip('visualization_msgs.msg')

STAMP_NS = 1_700_000_123_456_789_012  # an epoch stamp, ns


#: Specs for the parametrized round trips; fixed ids, as the params are not plain values.
SPECS = {
    'line-strip': scene_markers(full_scene(), 0.1)[0],
    'sphere': scene_markers(full_scene(), 0.1)[1],
    'cube-board': scene_markers(full_scene(), 0.1)[4],
    'delete': MarkerSpec('load', 0, Shape.CUBE, action=Action.DELETE),
    'long-lifetime': MarkerSpec(
        'x',
        7,
        Shape.SPHERE,
        position=(1e-9, -2.5, 3e3),
        color=(0.1, 0.2, 0.3, 0.4),
        lifetime_s=12.345678901,
    ),
}


@pytest.mark.parametrize('spec', list(SPECS.values()), ids=list(SPECS))
def test_a_marker_reads_the_same_in_rclpy(spec):
    data = serialize(marker_array([spec], STAMP_NS))
    message = serialization.deserialize_message(data, visualization_msgs.MarkerArray)
    (marker,) = message.markers
    assert marker.header.frame_id == FRAME_ID == 'beam_base'
    assert (marker.header.stamp.sec, marker.header.stamp.nanosec) == divmod(STAMP_NS, 10**9)
    assert (marker.ns, marker.id, marker.type, marker.action) == (
        spec.namespace,
        spec.marker_id,
        int(spec.shape),
        int(spec.action),
    )
    p, q = marker.pose.position, marker.pose.orientation
    assert (p.x, p.y, p.z) == spec.position and (q.x, q.y, q.z, q.w) == spec.orientation
    assert (marker.scale.x, marker.scale.y, marker.scale.z) == spec.scale
    color = (marker.color.r, marker.color.g, marker.color.b, marker.color.a)
    assert color == pytest.approx(spec.color, rel=1e-7)  # float32 on the wire
    lifetime = marker.lifetime.sec + marker.lifetime.nanosec * 1e-9
    assert lifetime == pytest.approx(spec.lifetime_s, abs=1e-9)
    assert 0 <= marker.lifetime.nanosec < 10**9
    assert [(v.x, v.y, v.z) for v in marker.points] == [tuple(p) for p in spec.points]
    assert marker.frame_locked is False and marker.text == '' and marker.mesh_resource == ''


@pytest.mark.parametrize('spec', list(SPECS.values()), ids=list(SPECS))
def test_a_marker_round_trips_through_rclpy(spec):
    # rclpy's own serializer writes bytes the package reads back into the same marker.
    message = serialization.deserialize_message(
        serialize(marker_array([spec], STAMP_NS)), visualization_msgs.MarkerArray
    )
    data = serialization.serialize_message(message)
    assert_same_markers(marker_specs(deserialize(data, MARKER_ARRAY_TYPE)), [spec])


def test_the_scene_bytes_are_the_scenes_marker_array():
    scene = full_scene()
    data = scene_cdr(scene, STAMP_NS, 0.1)
    assert data == serialize(marker_array(scene_markers(scene, 0.1), STAMP_NS))
    message = serialization.deserialize_message(data, visualization_msgs.MarkerArray)
    assert [m.ns for m in message.markers] == [
        'beam',
        'tip_measured',
        'tip_predicted',
        'load',
        'board',
    ]
    assert len(message.markers[0].points) == 11  # ten segments, eleven joints


def test_another_frame_is_carried():
    message = marker_message(SPECS['sphere'], 5, frame_id='world')
    assert message.header.frame_id == 'world' and message.header.stamp.nanosec == 5


@pytest.mark.parametrize(
    ('field', 'value', 'match'),
    [('type', 0, 'is not a valid Shape'), ('action', 3, 'is not a valid Action')],
    ids=['arrow', 'deleteall'],
)
def test_a_marker_this_package_does_not_draw_is_refused(field, value, match):
    marker = visualization_msgs.Marker()
    setattr(marker, field, value)
    if field == 'action':
        marker.type = int(Shape.CUBE)
    data = serialization.serialize_message(visualization_msgs.MarkerArray(markers=[marker]))
    with pytest.raises(ValueError, match=match):
        marker_specs(deserialize(data, MARKER_ARRAY_TYPE))


@pytest.fixture(scope='module')
def marker_bag(tmp_path_factory):
    """Three scenes at 10 Hz from an epoch stamp, then an empty array."""
    path = tmp_path_factory.mktemp('markers') / 'scenes'
    scenes = [
        full_scene(),
        full_scene(load_kg=0.0),
        BeamScene(SEGMENT_M, measured=TipPoint(2.3, -0.05)),
    ]
    with BagWriter(path) as bag:
        for i, scene in enumerate(scenes):
            write_scene(bag, 1_700_000_000.0 + 0.1 * i, scene, 0.3)
        bag.write_message(MARKERS_TOPIC, marker_array([], 0), 1_700_000_001_000_000_000)
    return path, scenes


def test_a_bag_gives_back_each_array_at_its_stamp(marker_bag):
    path, scenes = marker_bag
    arrays = list(read_marker_arrays(path))
    assert [t for t, _ in arrays] == pytest.approx(
        [1_700_000_000.0, 1_700_000_000.1, 1_700_000_000.2, 0.0], abs=1e-6
    )
    for (_, markers), scene in zip(arrays, scenes, strict=False):
        assert_same_markers(markers, scene_markers(scene, 0.3))
    assert arrays[-1][1] == []  # an empty array has no stamp to read
    reader = BagReader(path)
    assert reader.topics[MARKERS_TOPIC].msgtype == MARKER_ARRAY_TYPE
    assert reader.topics[MARKERS_TOPIC].count == 4
    log_times = [raw.log_time_ns for raw in reader.iter_raw([MARKERS_TOPIC])][:3]
    assert log_times == [
        1_700_000_000_000_000_000,
        1_700_000_000_100_000_000,
        1_700_000_000_200_000_000,
    ]


def test_a_bag_without_markers_is_a_bag_error(tmp_path):
    with BagWriter(tmp_path / 'poses') as bag:
        bag.write_pose('/tip_pose', 1.0, 2.3, -0.05, 0.02)
    with pytest.raises(BagError, match='/beam_markers'):
        list(read_marker_arrays(tmp_path / 'poses'))


def test_not_a_bag_is_a_bag_error(tmp_path):
    with pytest.raises(BagError):
        list(read_marker_arrays(tmp_path / 'missing'))


def test_the_points_keep_float64_precision():
    points = np.array([[math.pi, 0.0, -math.e], [1e-300, 0.0, 1e300]])
    spec = MarkerSpec('beam', 0, Shape.LINE_STRIP, points=points)
    (back,) = marker_specs(deserialize(serialize(marker_array([spec], 0)), MARKER_ARRAY_TYPE))
    np.testing.assert_array_equal(back.points, points)


def test_markers_of_a_frame_keep_its_integer_stamp_and_log_time(tmp_path):
    # Through float seconds, 1_700_000_000_123_456_789 ns comes back 21 ns off, enough to
    # put a tracked bag's markers out of log-time order.
    stamp, log_time = 1_700_000_000_123_456_789, 1_700_000_000_125_000_001
    with BagWriter(tmp_path / 'b') as bag:
        write_scene_ns(bag, stamp, full_scene(), 0.3, log_time_ns=log_time)
    [(logged, message)] = list(
        BagReader(tmp_path / 'b').messages(MARKERS_TOPIC, MARKER_ARRAY_TYPE)
    )
    header = message.markers[0].header.stamp
    assert (logged, header.sec * 1_000_000_000 + header.nanosec) == (log_time, stamp)
