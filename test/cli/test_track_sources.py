"""Footage of every kind a lab records, through ``lumpbeam track``, against the truth."""

import cv2
import numpy as np
import pytest
from footage import PATTERNS, grey_scene_mosaic, write_calibration, write_timestamps, write_video

from lumpbeam_ros.bagio import BagReader, BagWriter, convert, read_camera_info, read_tip_poses
from lumpbeam_ros.bagio.convert import seconds_to_ns
from lumpbeam_ros.cli.main import main
from lumpbeam_ros.vision.accuracy import drop_test_trajectory, render_frames
from lumpbeam_ros.vision.config import load_camera_config
from lumpbeam_ros.vision.messages import camera_info_to_data

WIDTH, HEIGHT = 640, 480
FPS = 180.0
START_S = 1.95
N_FRAMES = 40
#: Tip z and pitch: RMS of (tracked - truth), bias in it, over every frame.
LOSSLESS_Z_RMS_M, LOSSLESS_PITCH_RMS_RAD = 6e-6, 0.04e-3
#: JPEG at quality 90 (MJPG too) and a demosaiced Bayer mosaic: a micrometre or two more.
LOSSY_Z_RMS_M, LOSSY_PITCH_RMS_RAD = 8e-6, 0.06e-3


@pytest.fixture(scope='module')
def footage():
    """40 frames (0.22 s, the tip falling 80 mm) of the drop test at 640 x 480."""
    config = load_camera_config().with_resolution(WIDTH, HEIGHT)
    frames = render_frames(config, drop_test_trajectory().slice_time(START_S, 2.3), N_FRAMES)
    return config.camera_info, frames


def _stamps_ns(frames):
    return [seconds_to_ns(f.stamp) for f in frames]


def _bag(path, frames, encoding, info, with_info=True):
    with BagWriter(path) as bag:
        for frame, ns in zip(frames, _stamps_ns(frames), strict=True):
            if with_info:
                bag.write_message('/camera/camera_info', convert.camera_info(
                    ns, camera_info_to_data(info)), ns)  # fmt: skip
            image = frame.image
            if encoding in ('jpeg', 'png'):
                ext, params = ('.jpg', [cv2.IMWRITE_JPEG_QUALITY, 90]) if encoding == 'jpeg' else (
                    '.png', [])  # fmt: skip
                _, data = cv2.imencode(ext, image, params)
                msg = convert.compressed_image(ns, data.tobytes(), encoding, 'camera')
                bag.write_message('/camera/image_raw/compressed', msg, ns)
                continue
            if encoding in ('bgr8', 'rgb8'):
                image = np.repeat(image[..., None], 3, axis=2)
            elif encoding == 'mono16':  # a 12-bit sensor
                image = np.rint(image.astype(float) * 4095 / 255).astype(np.uint16)
            elif encoding in PATTERNS:
                image = grey_scene_mosaic(image, encoding)
            bag.write_message('/camera/image_raw', convert.image(ns, image, 'camera', encoding), ns)
    return path


def _folder(path, frames, ext):
    path.mkdir()
    for i, frame in enumerate(frames):
        params = [cv2.IMWRITE_JPEG_QUALITY, 90] if ext == '.jpg' else []
        cv2.imwrite(str(path / f'{i:05d}{ext}'), frame.image, params)
    return path


def _source(kind, tmp_path, footage):
    """Writes the footage as ``kind``; returns SRC and the options it needs."""
    info, frames = footage
    calibration = str(write_calibration(tmp_path / 'camera.yaml', info))
    stamps = str(write_timestamps(tmp_path / 'stamps.txt', _stamps_ns(frames)))
    fps = ['--fps', str(FPS), '--start-time', str(START_S)]
    medium, _, detail = kind.partition(' ')
    if medium == 'bag':
        # The compressed bag has no camera_info: its intrinsics come from the file.
        with_info = detail != 'jpeg'
        src = _bag(tmp_path / 'in', frames, detail, info, with_info)
        return src, [] if with_info else ['--camera-info', calibration]
    if medium == 'video':
        fourcc, ext = {'MJPG': ('MJPG', '.avi'), 'FFV1': ('FFV1', '.mkv')}[detail]
        src = write_video(tmp_path / f'clip{ext}', [f.image for f in frames], fourcc)
        timing = fps if detail == 'MJPG' else ['--timestamps', stamps]
        return src, ['--camera-info', calibration, *timing]
    src = _folder(tmp_path / 'frames', frames, detail)
    timing = ['--timestamps', stamps] if detail == '.png' else fps
    return src, ['--camera-info', calibration, *timing]


LOSSLESS = ['bag mono8', 'bag mono16', 'bag bgr8', 'bag rgb8', 'bag png', 'video FFV1',
            'folder .png']  # fmt: skip
LOSSY = ['bag jpeg', *(f'bag {p}' for p in sorted(PATTERNS)), 'video MJPG', 'folder .jpg']


def _errors(out, frames):
    poses = read_tip_poses(out)
    truth = np.array([f.truth for f in frames])
    return poses, np.column_stack([poses.x, poses.z, poses.pitch]) - truth


@pytest.mark.parametrize('kind', LOSSLESS + LOSSY)
def test_every_kind_of_footage_is_tracked_against_the_truth(kind, tmp_path, footage, capsys):
    info, frames = footage
    src, options = _source(kind, tmp_path, footage)
    out = tmp_path / 'out'
    assert main(['track', str(src), str(out), '--quiet', *options]) == 0
    printed = capsys.readouterr()
    assert f'{N_FRAMES} frames, {N_FRAMES} poses, 0 lost' in printed.out, printed
    assert printed.err == ''  # --quiet, and nothing to warn about
    poses, error = _errors(out, frames)
    # Every pose carries its frame's stamp, to the nanosecond (an --fps stamp rounds the same).
    np.testing.assert_array_equal(
        np.round(poses.t * 1e9).astype(np.int64) // 1000, np.array(_stamps_ns(frames)) // 1000
    )
    rms = np.sqrt(np.mean(error**2, axis=0))
    bias, worst = error.mean(axis=0), np.max(np.abs(error), axis=0)
    print(
        f'\n{kind:20s} {len(poses.t)} poses: z rms {rms[1] * 1e6:.2f} um (bias '
        f'{bias[1] * 1e6:+.2f}, max {worst[1] * 1e6:.2f}), pitch rms {rms[2] * 1e3:.4f} mrad '
        f'(bias {bias[2] * 1e3:+.4f}), x rms {rms[0] * 1e6:.1f} um'
    )
    z_limit, pitch_limit = (
        (LOSSLESS_Z_RMS_M, LOSSLESS_PITCH_RMS_RAD) if kind in LOSSLESS
        else (LOSSY_Z_RMS_M, LOSSY_PITCH_RMS_RAD)
    )  # fmt: skip
    assert rms[1] < z_limit and rms[2] < pitch_limit
    medium = kind.split()[0]
    if medium != 'bag':
        # OUT of a video or a folder: the poses and the intrinsics used.
        assert set(BagReader(out).topics) == {'/tip_pose', '/camera/camera_info'}
        np.testing.assert_array_equal(read_camera_info(out).k, info.k)


def test_lossless_kinds_give_exactly_the_mono8_poses(tmp_path, footage):
    tracked = {}
    for kind in LOSSLESS:
        folder = tmp_path / kind.replace(' ', '_')
        folder.mkdir()
        src, options = _source(kind, folder, footage)
        assert main(['track', str(src), str(folder / 'out'), '--quiet', *options]) == 0
        poses = read_tip_poses(folder / 'out')
        tracked[kind] = np.column_stack([poses.z, poses.pitch])
    for kind in LOSSLESS[1:]:
        np.testing.assert_array_equal(tracked[kind], tracked['bag mono8'], err_msg=kind)
