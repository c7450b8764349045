import math

import numpy as np
import pytest

from lumpbeam_ros.base.errors import BagError
from lumpbeam_ros.core.bagio import convert
from lumpbeam_ros.core.bagio.typestore import deserialize, serialize


@pytest.mark.parametrize('pitch', [-1.2, -0.03, 0.0, 0.0123, 0.5, 2.5])
def test_pitch_round_trip(pitch):
    q = convert.pitch_to_quaternion(pitch)
    assert math.isclose(convert.quaternion_to_pitch(*q), pitch, abs_tol=1e-12)


def test_positive_pitch_points_the_tip_down():
    # Rotating e_x by +pitch about +y must give a negative z component (REP-103).
    qx, qy, qz, qw = convert.pitch_to_quaternion(0.3)
    d_z = 2.0 * (qx * qz - qw * qy)
    assert d_z == pytest.approx(-math.sin(0.3))


def test_pitch_ignores_normalization_and_a_broken_quaternion_is_nan():
    qx, qy, qz, qw = convert.pitch_to_quaternion(0.4)
    assert convert.quaternion_to_pitch(3 * qx, 3 * qy, 3 * qz, 3 * qw) == pytest.approx(0.4)
    assert math.isnan(convert.quaternion_to_pitch(0.0, 0.0, 0.0, 0.0))
    pitch = convert.quaternions_to_pitch(np.array([[qx, qy, qz, qw], [math.nan, 0, 0, 1]]))
    assert pitch[0] == pytest.approx(0.4) and math.isnan(pitch[1])


def test_pose_survives_cdr():
    msg = convert.pose_stamped(1_700_000_000_123_456_789, 2.31, -0.047, 0.031, 'beam_base')
    back = deserialize(serialize(msg), 'geometry_msgs/msg/PoseStamped')
    ns, x, z, pitch, frame = convert.pose_values(back)
    assert (ns, x, z, frame) == (1_700_000_000_123_456_789, 2.31, -0.047, 'beam_base')
    assert pitch == pytest.approx(0.031, abs=1e-15)


@pytest.mark.parametrize('seconds', [-1.0, float('nan'), float('inf')])
def test_bad_times_are_rejected(seconds):
    with pytest.raises(BagError, match='time'):
        convert.seconds_to_ns(seconds)


@pytest.mark.parametrize(
    ('encoding', 'shape'), [('mono8', (4, 5)), ('bgr8', (4, 5, 3)), ('rgb8', (2, 3, 3))]
)
def test_image_round_trip(encoding, shape):
    pixels = np.random.default_rng(1).integers(0, 256, shape, dtype=np.uint8)
    data = serialize(convert.image(5, pixels, 'cam', encoding))
    msg = deserialize(data, 'sensor_msgs/msg/Image')
    assert msg.step == shape[1] * (1 if len(shape) == 2 else 3)
    np.testing.assert_array_equal(convert.image_array(msg), pixels)


def test_image_with_row_padding_drops_the_padding():
    pixels = np.arange(12, dtype=np.uint8).reshape(3, 4)
    msg = convert.image(0, pixels, 'cam')
    padded = np.zeros((3, 8), dtype=np.uint8)
    padded[:, :4] = pixels
    msg.step, msg.data = 8, padded.reshape(-1)
    np.testing.assert_array_equal(convert.image_array(msg), pixels)


@pytest.mark.parametrize(
    ('field', 'value', 'match'),
    [
        ('encoding', '16UC1', 'unsupported image encoding'),
        ('step', 3, 'shorter than'),
        ('height', 4, 'expected step'),
        ('data', np.zeros(5, dtype=np.uint8), 'expected step'),
    ],
)
def test_malformed_images_are_rejected(field, value, match):
    msg = convert.image(0, np.zeros((3, 4), dtype=np.uint8), 'cam')
    setattr(msg, field, value)
    with pytest.raises(BagError, match=match):
        convert.image_array(msg)


@pytest.mark.parametrize(
    ('pixels', 'encoding', 'match'),
    [
        (np.zeros((3, 4), dtype=np.uint16), None, 'uint8'),
        (np.zeros((3, 4), dtype=np.uint8), 'bgr8', 'does not fit'),
        (np.zeros((3, 4, 4), dtype=np.uint8), None, 'does not fit'),
        (np.zeros((3, 4), dtype=np.uint8), 'yuv422', 'unsupported'),
    ],
)
def test_bad_arrays_are_rejected(pixels, encoding, match):
    with pytest.raises(BagError, match=match):
        convert.image(0, pixels, 'cam', encoding)


def test_camera_info_round_trip():
    k = np.array([[900.0, 0, 512], [0, 900.0, 384], [0, 0, 1]])
    info = convert.CameraInfoData(1024, 768, k, d=np.array([0.1, -0.02, 0, 0, 0.001]))
    msg = deserialize(serialize(convert.camera_info(7, info)), 'sensor_msgs/msg/CameraInfo')
    back = convert.camera_info_data(msg)
    assert (back.width, back.height, back.frame_id) == (1024, 768, 'camera')
    np.testing.assert_array_equal(back.k, k)
    np.testing.assert_array_equal(back.p[:, :3], k)
    np.testing.assert_array_equal(back.d, info.d)


def test_camera_info_with_wrong_matrix_shape_is_rejected():
    with pytest.raises(BagError, match='3x3'):
        convert.camera_info(0, convert.CameraInfoData(10, 10, np.eye(2)))


def test_diagnostics_round_trip():
    status = convert.Status('lumpbeam/identifier', 1, 'low confidence', {'damping_ratio': '0.02'})
    msg = convert.diagnostic_array(3, [status])
    back = convert.diagnostic_statuses(
        deserialize(serialize(msg), 'diagnostic_msgs/msg/DiagnosticArray')
    )
    assert back == [status]
    with pytest.raises(BagError, match='level'):
        convert.diagnostic_array(3, [convert.Status('x', 7, '')])


def test_point_and_clock_round_trip():
    msg = deserialize(
        serialize(convert.point_stamped(9, 1.0, 2.0, -3.0, 'tracker')),
        'geometry_msgs/msg/PointStamped',
    )
    assert convert.point_values(msg) == (9, 1.0, 2.0, -3.0, 'tracker')
    clock = deserialize(serialize(convert.clock(12_000_000_001)), 'rosgraph_msgs/msg/Clock')
    assert convert.time_ns(clock.clock) == 12_000_000_001


def test_joint_state_round_trip():
    from lumpbeam_ros.core.bagio.convert import joint_state, joint_state_values
    from lumpbeam_ros.core.bagio.typestore import serialize

    msg = joint_state(1_500_000_000, ['joint_1', 'joint_2'], np.array([0.25, -1.5]))
    assert msg.__msgtype__ == 'sensor_msgs/msg/JointState'
    assert serialize(msg)  # the typestore knows the type
    stamp, names, positions = joint_state_values(msg)
    assert stamp == 1_500_000_000 and names == ['joint_1', 'joint_2']
    assert positions.tolist() == [0.25, -1.5]
    assert msg.velocity.size == 0 and msg.effort.size == 0
