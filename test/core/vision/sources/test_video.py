import itertools

import numpy as np
import pytest
from footage import write_timestamps, write_video

from lumpbeam_ros.core.vision.sources import DeviceSource, FootageError, FrameStamps, VideoSource


def _images(n=6):
    # A bright square moving right: frame i has its left edge at column 8 + 4 i.
    images = []
    for i in range(n):
        image = np.full((48, 64), 30, np.uint8)
        image[16:32, 8 + 4 * i : 24 + 4 * i] = 220
        images.append(image)
    return images


def test_video_frames_come_in_order_with_their_stamps(tmp_path):
    images = _images()
    path = write_video(tmp_path / 'clip.mkv', images, 'FFV1')
    source = VideoSource(path, FrameStamps.from_fps(100.0, 2.0))
    assert source.total == len(images)
    frames = list(source)
    assert [f.stamp_ns for f in frames] == [2_000_000_000 + 10_000_000 * i for i in range(6)]
    assert frames[3].label == 'clip.mkv frame 3' and frames[3].encoding == 'bgr8'
    for frame, image in zip(frames, images, strict=True):
        np.testing.assert_array_equal(frame.pixels[..., 1], image)  # FFV1 is lossless


def test_a_device_is_stamped_by_its_clock_through_the_same_reader(tmp_path):
    path = write_video(tmp_path / 'clip.avi', _images(), 'MJPG')
    ticks = itertools.count(1_000_000_000, 3_000_000)
    frames = list(DeviceSource(str(path), clock_ns=lambda: next(ticks)))
    assert [f.stamp_ns for f in frames] == [1_000_000_000 + 3_000_000 * i for i in range(6)]
    assert frames[0].label == f'video device {path} frame 0'


@pytest.mark.parametrize('case', ['not a video', 'missing', 'too few stamps', 'no device'])
def test_bad_videos_are_one_line(tmp_path, case):
    path = tmp_path / 'clip.avi'
    stamps = FrameStamps.from_fps(30.0)
    if case == 'not a video':
        path.write_text('this is not a video\n')
    elif case == 'too few stamps':
        write_video(path, _images(), 'MJPG')
        stamps = FrameStamps.from_file(write_timestamps(tmp_path / 't.txt', [1, 2, 3]))
    with pytest.raises(FootageError) as error:
        if case == 'no device':
            DeviceSource(str(tmp_path / 'video99'))
        else:
            VideoSource(path, stamps)
    expected = {
        'not a video': 'clip.avi: OpenCV cannot open it',
        'missing': 'clip.avi: no such video file',
        'too few stamps': 't.txt has 3 stamps but',
        'no device': 'video device',
    }[case]
    assert expected in str(error.value) and '\n' not in str(error.value)
