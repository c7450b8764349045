"""Camera messages from rclpy's serializer to tracker inputs: every encoding, bad bytes."""

import cv2
import numpy as np
import pytest

from lumpbeam_ros.base.errors import BagError, LumpbeamError
from lumpbeam_ros.base.interface import (
    CAMERA_FRAME,
    CAMERA_INFO_TYPE,
    COMPRESSED_IMAGE_TYPE,
    IMAGE_TYPE,
)
from lumpbeam_ros.core.bagio import convert
from lumpbeam_ros.core.bagio.typestore import serialize, typestore
from lumpbeam_ros.core.vision.camera_model import CameraInfo
from lumpbeam_ros.core.vision.messages import (
    IMAGE_TYPES,
    CameraFrame,
    camera_info_from_data,
    camera_info_to_data,
    decode_camera_info,
    decode_compressed_image,
    decode_frame,
    decode_image,
    prepare_decoders,
)

from .helpers import STAMP_NS, camera_info_cdr, compressed_cdr, encoded, image_cdr

RNG = np.random.default_rng(4)
GREY = RNG.integers(0, 256, (6, 10), dtype=np.uint8)
COLOUR = RNG.integers(0, 256, (6, 10, 3), dtype=np.uint8)
K = np.array([[800.0, 0.0, 319.5], [0.0, 801.0, 239.5], [0.0, 0.0, 1.0]])
D = np.array([-0.1, 0.02, 1e-4, -2e-4, 0.0])


@pytest.mark.parametrize(
    ('pixels', 'encoding', 'padding'),
    [(GREY, 'mono8', 0), (GREY, 'mono8', 6), (COLOUR, 'bgr8', 0), (COLOUR, 'rgb8', 2)],
    ids=['mono8', 'mono8-padded', 'bgr8', 'rgb8-padded'],
)
def test_tracker_encodings_come_out_as_they_went_in(pixels, encoding, padding):
    frame = decode_image(image_cdr(pixels, encoding, padding=padding))
    assert isinstance(frame, CameraFrame)
    assert frame.encoding == encoding and frame.frame_id == 'camera_optical'
    np.testing.assert_array_equal(frame.pixels, pixels)
    assert frame.stamp_ns == STAMP_NS  # exact, to the nanosecond
    assert frame.stamp == pytest.approx(1_700_000_000.123456789, abs=1e-6)


@pytest.mark.parametrize(
    ('top', 'full_scale'),
    [(255, 255), (1023, 1023), (4095, 4095), (4000, 4095), (65535, 65535)],
    ids=['8-bit', '10-bit', '12-bit', '12-bit-not-full', '16-bit'],
)
def test_mono16_is_scaled_by_its_bit_depth(top, full_scale):
    pixels = np.array([[0, top // 2, top], [1, 2, 3]], dtype=np.uint16)
    frame = decode_image(image_cdr(pixels, 'mono16'))
    assert frame.encoding == 'mono8' and frame.pixels.dtype == np.uint8
    expected = np.floor(pixels * (255.0 / full_scale) + 0.5)
    np.testing.assert_array_equal(frame.pixels, expected)


@pytest.mark.parametrize('pattern', ['bayer_rggb8', 'bayer_bggr8', 'bayer_gbrg8', 'bayer_grbg8'])
def test_a_bayer_mosaic_of_a_grey_scene_is_that_grey(pattern):
    # A neutral scene gives equal samples whatever the filter: demosaiced, the same grey.
    frame = decode_image(image_cdr(np.full((8, 12), 117, np.uint8), pattern))
    assert frame.encoding == 'mono8' and frame.pixels.shape == (8, 12)
    assert np.all(frame.pixels == 117)


@pytest.mark.parametrize(
    ('data', 'match'),
    [
        (image_cdr(GREY, '32FC1'), 'unsupported image encoding'),
        (image_cdr(GREY, 'yuv422'), 'unsupported image encoding'),
        (image_cdr(GREY[:, :9], 'bgr8'), 'data has|shorter than'),
        (b'\x00\x01\x00\x00\xff', r'corrupt sensor_msgs/msg/Image message \(5 bytes\)'),
        (b'', r'corrupt sensor_msgs/msg/Image message \(0 bytes\)'),
        # Refused before any copy of its pixels: a 20000 x 20000 frame is 400 MB a copy.
        (image_cdr(np.zeros((1, 20000), np.uint8), 'mono8'), r'bad image size 20000 x 1'),
    ],
    ids=['float', 'yuv', 'size-mismatch', 'corrupt', 'empty', 'too wide'],
)
def test_a_bad_image_is_a_bag_error(data, match):
    with pytest.raises(BagError, match=match) as info:
        decode_image(data)
    assert '\n' not in str(info.value)


@pytest.mark.parametrize(
    ('file_format', 'pixels', 'encoding', 'tolerance'),
    [
        ('PNG', GREY, 'mono8', 0),
        ('PNG', COLOUR, 'bgr8', 0),
        ('JPEG', np.full((16, 16), 90, np.uint8), 'mono8', 1),
    ],
    ids=['png-grey', 'png-colour', 'jpeg-grey'],
)
def test_compressed_images_decode_to_the_encoded_pixels(file_format, pixels, encoding, tolerance):
    data = compressed_cdr(encoded(pixels, file_format), file_format.lower())
    frame = decode_compressed_image(data)
    assert frame.encoding == encoding and frame.stamp_ns == STAMP_NS
    # Pillow writes RGB; a colour image comes out in OpenCV's BGR order.
    expected = pixels[..., ::-1] if encoding == 'bgr8' else pixels
    assert np.max(np.abs(frame.pixels.astype(int) - expected)) <= tolerance
    assert decode_frame(data, COMPRESSED_IMAGE_TYPE).encoding == encoding


@pytest.mark.parametrize(
    ('payload', 'image_format', 'match'),
    [
        (b'', 'png', 'corrupt or undecodable'),
        (b'not an image', 'png', 'corrupt or undecodable'),
        ('truncated-jpeg', 'jpeg', 'no end-of-image marker'),
        ('png', '16UC1; compressedDepth png', 'depth image'),
    ],
    ids=['empty', 'garbage', 'truncated-jpeg', 'depth'],
)
def test_a_bad_compressed_image_is_a_bag_error(payload, image_format, match):
    if payload == 'truncated-jpeg':
        payload = encoded(np.full((64, 64), 90, np.uint8), 'JPEG')[:-200]
    elif payload == 'png':
        payload = encoded(GREY, 'PNG')
    with pytest.raises(BagError, match=match):
        decode_compressed_image(compressed_cdr(payload, image_format))


def test_decode_frame_picks_the_type():
    raw = image_cdr(GREY, 'mono8')
    np.testing.assert_array_equal(decode_frame(raw).pixels, GREY)
    np.testing.assert_array_equal(decode_frame(raw, IMAGE_TYPE).pixels, GREY)
    assert IMAGE_TYPES == (IMAGE_TYPE, COMPRESSED_IMAGE_TYPE)


def test_the_decoders_are_ready_before_the_first_frame():
    typestore.cache_clear()  # a store that has decoded nothing yet
    prepare_decoders()
    assert {*IMAGE_TYPES, CAMERA_INFO_TYPE} <= set(typestore().cache)


def test_another_type_is_not_an_image():
    with pytest.raises(BagError, match='sensor_msgs/msg/CameraInfo is not an image type'):
        decode_frame(image_cdr(GREY, 'mono8'), 'sensor_msgs/msg/CameraInfo')


def test_a_camera_info_from_rclpy_is_the_camera_model():
    info = decode_camera_info(camera_info_cdr(640, 480, K, D))
    assert (info.width, info.height, info.distortion_model) == (640, 480, 'plumb_bob')
    np.testing.assert_array_equal(info.k, K)
    np.testing.assert_array_equal(info.d, D)


@pytest.mark.parametrize(
    ('width', 'k', 'd', 'model', 'match'),
    [
        (640, np.zeros((3, 3)), D, 'plumb_bob', 'K = 0'),
        (640, K, D, 'fov', "distortion model 'fov' is not supported"),
        (640, K, D, 'equidistant', 'equidistant needs 4 finite coefficients, got 5'),
        (640, K, D[:3], 'plumb_bob', 'plumb_bob needs 5 finite coefficients, got 3'),
        (0, K, D, 'plumb_bob', 'bad image size 0 x 480'),
    ],
    ids=['uncalibrated', 'fov', 'fisheye-five', 'short-d', 'no-size'],
)
def test_an_unusable_camera_info_is_one_clear_error(width, k, d, model, match):
    with pytest.raises(LumpbeamError, match=match):
        decode_camera_info(camera_info_cdr(width, 480, k, d, model))


def test_a_corrupt_camera_info_is_a_bag_error():
    with pytest.raises(BagError):
        decode_camera_info(b'\x00\x01\x00\x00\x01')


def test_the_camera_model_round_trips_through_a_message():
    info = CameraInfo(640, 480, K, D)
    data = camera_info_to_data(info)
    assert data.frame_id == CAMERA_FRAME
    back = decode_camera_info(serialize(convert.camera_info(STAMP_NS, data)))
    assert (back.width, back.height, back.distortion_model) == (640, 480, 'plumb_bob')
    np.testing.assert_array_equal(back.k, K)
    np.testing.assert_array_equal(back.d, D)
    message = convert.camera_info(STAMP_NS, camera_info_to_data(info, 'other_frame'))
    assert message.header.frame_id == 'other_frame'
    np.testing.assert_array_equal(message.p.reshape(3, 4), np.hstack([K, np.zeros((3, 1))]))


def test_camera_info_to_data_copies_the_matrices():
    info = CameraInfo(640, 480, K, D)
    data = camera_info_to_data(info)
    data.k[0, 0] = 1.0
    assert info.k[0, 0] == 800.0
    assert camera_info_from_data(camera_info_to_data(info)).k[0, 0] == 800.0


def test_opencv_reads_the_decoded_colour_as_bgr():
    # Independent of the package: OpenCV's own PNG writer, read back through the message.
    ok, png = cv2.imencode('.png', COLOUR)
    assert ok
    frame = decode_compressed_image(compressed_cdr(png.tobytes(), 'png'))
    np.testing.assert_array_equal(frame.pixels, COLOUR)
