import dataclasses

import numpy as np
import pytest

from lumpbeam_lab.camera.accuracy import render_frames
from lumpbeam_ros.base.interface import CAMERA_INFO, IMAGE, IMAGE_TYPE, TIP_LOAD
from lumpbeam_ros.core.bagio import BagReader, BagWriter, convert
from lumpbeam_ros.core.vision.bag_frames import bag_frames
from lumpbeam_ros.core.vision.messages import camera_info_to_data
from lumpbeam_ros.core.vision.session import TrackingSession


@pytest.fixture(scope='module')
def bag(config, drop_test, tmp_path_factory):
    """Calibration, a load, four frames (the third corrupt), a K = 0 calibration, then one."""
    frames = render_frames(config, drop_test.between(1.98, 2.1), 5)
    calibration = camera_info_to_data(config.camera_info)
    path = tmp_path_factory.mktemp('frames') / 'bag'
    with BagWriter(path) as writer:
        writer.add_topic(IMAGE, IMAGE_TYPE)
        writer.write_camera_info(CAMERA_INFO, frames[0].stamp - 0.005, calibration)
        writer.write_float(TIP_LOAD, frames[0].stamp - 0.004, 4.5)
        for i, f in enumerate(frames):
            if i == 4:
                zero = dataclasses.replace(calibration, k=np.zeros((3, 3)))
                writer.write_camera_info(CAMERA_INFO, f.stamp - 1e-4, zero)
            if i == 2:
                writer.write_raw(IMAGE, convert.seconds_to_ns(f.stamp), b'\x00\x01\x00\x00\xff')
            else:
                writer.write_image(IMAGE, f.stamp, f.image)
    return path, frames


def _walk(bag, config, **options):
    path, _ = bag
    session = TrackingSession(config)
    items = list(bag_frames(BagReader(path), session, IMAGE, IMAGE_TYPE, CAMERA_INFO, **options))
    return session, items


def test_every_message_comes_out_once_in_order_and_said_what_it_was(bag, config):
    session, items = _walk(bag, config)
    _, frames = bag
    assert [item.kind for item in items] == [
        'camera_info', 'other', 'image', 'image', 'image', 'image', 'camera_info', 'image'
    ]  # fmt: skip
    images = [item for item in items if item.kind == 'image']
    assert [item.index for item in images] == [0, 1, 2, 3, 4]
    assert [item.frame is None for item in images] == [False, False, True, False, False]
    assert images[2].problem.startswith('corrupt')
    stamps = [item.frame.stamp_ns for item in images if item.frame is not None]
    assert stamps == [convert.seconds_to_ns(f.stamp) for i, f in enumerate(frames) if i != 2]
    first, bad = (item for item in items if item.kind == 'camera_info')
    assert first.info_changed and not first.problem
    assert not bad.info_changed and bad.problem  # K = 0: the tracker in use is kept
    assert session.camera_info is not None and session.camera_info.k[0, 0] > 0


def test_the_calibration_left_alone_is_an_other_message(bag, config):
    session, items = _walk(bag, config, follow_info=False)
    assert [item.kind for item in items].count('camera_info') == 0
    assert session.camera_info is None


def test_a_stop_ends_the_walk_and_topics_choose_what_is_read(bag, config):
    path, _ = bag
    seen = []
    walk = bag_frames(
        BagReader(path), TrackingSession(config), IMAGE, IMAGE_TYPE, CAMERA_INFO,
        topics=[IMAGE], should_stop=lambda: len(seen) >= 2,
    )  # fmt: skip
    for item in walk:
        seen.append(item)
    assert [item.kind for item in seen] == ['image', 'image']
