import cv2
import numpy as np
import pytest
from footage import PATTERNS, grey_scene_mosaic, mosaic

from lumpbeam_ros.base.errors import BagError
from lumpbeam_ros.core.vision.sources.pixels import (
    decode_compressed,
    mono16_to_mono8,
    tracker_pixels,
)


@pytest.mark.parametrize('encoding', sorted(PATTERNS))
def test_bayer_patterns_follow_the_ros_names(encoding):
    # Flat colour planes R 200, G 100, B 50: the grey a demosaic gives tells the pattern it
    # assumed, since swapping red and blue changes the luma.
    shape = (32, 48)
    planes = {c: np.full(shape, v, np.uint8) for c, v in (('R', 200), ('G', 100), ('B', 50))}
    grey, encoding_out = tracker_pixels(mosaic(planes, encoding), encoding)
    assert encoding_out == 'mono8' and grey.shape == shape
    luma = 0.299 * 200 + 0.587 * 100 + 0.114 * 50
    swapped = 0.299 * 50 + 0.587 * 100 + 0.114 * 200
    centre = grey[4:-4, 4:-4].astype(float)
    # OpenCV 4's demosaic rounds 1 DN lower than OpenCV 5's (123 and 124 for 124.2); a
    # swap is 28 DN off.
    assert np.all(np.abs(centre - luma) <= 1.5), (centre.min(), centre.max(), swapped)


def test_bayer_demosaic_keeps_full_resolution_edges():
    # A vertical edge at every column position: the demosaiced grey must step within a pixel
    # or two of it, not at the 2-pixel pitch of one colour plane.
    mono = np.full((16, 64), 40, np.uint8)
    mono[:, 33:] = 210
    grey, _ = tracker_pixels(grey_scene_mosaic(mono, 'bayer_rggb8'), 'bayer_rggb8')
    row = grey[8].astype(float)
    assert row[:31].std() < 1.0 and row[35:].std() < 1.0
    assert row[31] < row[33] < row[35]
    # Half-way between the two levels at the edge (x = 32.5), not a pixel off.
    crossing = np.interp((row[:31].mean() + row[35:].mean()) / 2, row[28:38], np.arange(28, 38))
    assert abs(crossing - 32.5) < 0.5


@pytest.mark.parametrize('bits', [8, 10, 12, 14, 16])
def test_mono16_is_scaled_by_its_bit_depth(bits):
    mono = np.arange(256, dtype=np.uint8).reshape(16, 16)
    full = (1 << bits) - 1
    wide = np.rint(mono.astype(float) * full / 255).astype(np.uint16)
    np.testing.assert_array_equal(mono16_to_mono8(wide), mono)


def test_compressed_png_and_jpeg_decode():
    mono = (np.indices((40, 60)).sum(axis=0) % 2 * 180 + 30).astype(np.uint8)
    _, png = cv2.imencode('.png', mono)
    pixels, encoding = decode_compressed(png.tobytes(), 'png')
    assert encoding == 'mono8'
    np.testing.assert_array_equal(pixels, mono)
    _, jpeg = cv2.imencode('.jpg', cv2.cvtColor(mono, cv2.COLOR_GRAY2BGR))
    pixels, encoding = decode_compressed(jpeg.tobytes(), 'bgr8; jpeg compressed bgr8')
    assert encoding == 'bgr8' and pixels.shape == (40, 60, 3)
    _, png16 = cv2.imencode('.png', mono.astype(np.uint16) * 257)
    pixels, encoding = decode_compressed(png16.tobytes(), 'png')
    np.testing.assert_array_equal(pixels, mono)


@pytest.mark.parametrize(
    ('case', 'match'),
    [
        ('truncated jpeg', 'no end-of-image marker'),
        ('garbage', 'corrupt or undecodable'),
        ('empty', 'corrupt or undecodable'),
        ('depth', 'depth image'),
    ],
)
def test_corrupt_compressed_images_are_refused(case, match):
    _, jpeg = cv2.imencode('.jpg', np.full((40, 60), 128, np.uint8))
    data, image_format = {
        'truncated jpeg': (jpeg.tobytes()[: jpeg.size // 2], 'jpeg'),
        'garbage': (bytes(range(256)) * 4, 'jpeg'),
        'empty': (b'', 'png'),
        'depth': (jpeg.tobytes(), '16UC1; compressedDepth png'),
    }[case]
    with pytest.raises(BagError, match=match):
        decode_compressed(data, image_format)


@pytest.mark.parametrize(
    ('pixels', 'encoding', 'match'),
    [
        (np.zeros((4, 4), np.uint8), '16UC1', 'unsupported image encoding'),
        (np.zeros((4, 4, 3), np.uint8), 'bayer_rggb8', 'one channel'),
        (np.zeros((4, 4), np.uint8), 'mono16', 'uint16'),
    ],
)
def test_bad_pixels_are_refused(pixels, encoding, match):
    with pytest.raises(BagError, match=match):
        tracker_pixels(pixels, encoding)
