"""Footage of every kind a lab records, through ``lumpbeam track``, against the truth."""

import io
import sys

import cv2
import numpy as np
import pytest
from footage import PATTERNS, grey_scene_mosaic, write_calibration, write_timestamps, write_video

from lumpbeam_lab.camera.accuracy import drop_test_trajectory, render_frames
from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.core.bagio import BagReader, BagWriter, convert, read_camera_info, read_tip_poses
from lumpbeam_ros.core.bagio.convert import seconds_to_ns
from lumpbeam_ros.core.vision.config import load_camera_config
from lumpbeam_ros.core.vision.messages import camera_info_to_data

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
    frames = render_frames(config, drop_test_trajectory().between(START_S, 2.3), N_FRAMES)
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
            msg = convert.image(ns, image, 'camera', encoding)
            bag.write_message('/camera/image_raw', msg, ns)
    return path


def _folder(path, frames, kind):
    """Writes the frames as files; ``kind`` is the extension, then ``16-bit`` or ``colour``."""
    ext, _, detail = kind.partition(' ')
    path.mkdir()
    for i, frame in enumerate(frames):
        params = [cv2.IMWRITE_JPEG_QUALITY, 90] if ext == '.jpg' else []
        image = frame.image
        if detail == '16-bit':  # the full 16-bit range, as a 16-bit camera's files have it
            image = image.astype(np.uint16) * 257
        elif detail == 'colour':
            image = cv2.cvtColor(image, cv2.COLOR_GRAY2BGR)
        cv2.imwrite(str(path / f'{i:05d}{ext}'), image, params)
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
            'folder .png', 'folder .png 16-bit', 'folder .tif']  # fmt: skip
LOSSY = ['bag jpeg', *(f'bag {p}' for p in sorted(PATTERNS)), 'video MJPG', 'folder .jpg',
         'folder .jpg colour']  # fmt: skip


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
        # OUT of a video or a folder: the poses, the intrinsics used and the markers to view.
        topics = set(BagReader(out).topics)
        assert topics == {'/tip_pose', '/camera/camera_info', '/beam_markers'}
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


def _bad_source(case, tmp_path, footage):
    """Writes a broken input; returns SRC and the options."""
    info, frames = footage
    few = frames[:6]
    calibration = str(write_calibration(tmp_path / 'camera.yaml', info))
    fps = ['--fps', '30']
    if case == 'unsupported distortion model':
        bad = write_calibration(tmp_path / 'fisheye.yaml', info, model='kannala_brandt_x')
        return _folder(tmp_path / 'frames', few, '.png'), ['--camera-info', str(bad), *fps]
    if case == 'camera matrix of zeros':
        bad = write_calibration(tmp_path / 'zero.yaml', info, k=[0.0] * 9)
        return _folder(tmp_path / 'frames', few, '.png'), ['--camera-info', str(bad), *fps]
    if case == 'camera_info of another size':
        small = info.scaled(320, 240)
        return _bag(tmp_path / 'in', few, 'mono8', small), []
    if case == 'calibration of another size':
        other = write_calibration(tmp_path / 'other.yaml', info.scaled(320, 240))
        return _folder(tmp_path / 'frames', few, '.png'), ['--camera-info', str(other), *fps]
    if case == 'unreadable video':
        (tmp_path / 'clip.avi').write_bytes(b'RIFF' + bytes(200))
        return tmp_path / 'clip.avi', ['--camera-info', calibration, *fps]
    if case == 'image folder with mixed sizes':
        folder = _folder(tmp_path / 'frames', few, '.png')
        cv2.imwrite(str(folder / '00003.png'), cv2.resize(few[3].image, (320, 240)))
        return folder, ['--camera-info', calibration, *fps]
    if case == 'timestamps file shorter than the video':
        src = write_video(tmp_path / 'clip.avi', [f.image for f in few], 'MJPG')
        stamps = write_timestamps(tmp_path / 'stamps.txt', _stamps_ns(few)[:4])
        return src, ['--camera-info', calibration, '--timestamps', str(stamps)]
    if case == 'no frames at all':
        (tmp_path / 'frames').mkdir()
        return tmp_path / 'frames', ['--camera-info', calibration, *fps]
    if case == 'video without --fps or --timestamps':
        src = write_video(tmp_path / 'clip.avi', [f.image for f in few], 'MJPG')
        return src, ['--camera-info', calibration]
    if case == 'folder without --fps or --timestamps':
        return _folder(tmp_path / 'frames', few, '.png'), ['--camera-info', calibration]
    if case == 'video without --camera-info':
        return write_video(tmp_path / 'clip.avi', [f.image for f in few], 'MJPG'), fps
    if case == 'bad --board':
        return _bag(tmp_path / 'in', few, 'mono8', info), ['--board', '7x7']
    raise AssertionError(case)


BAD_INPUTS = {
    # The camera model's own words follow the file's name (and the model's name).
    'unsupported distortion model': 'fisheye.yaml: camera info: ',
    'camera matrix of zeros': 'zero.yaml: camera info: ',
    'camera_info of another size': (
        'in /camera/image_raw message 0: image is 640 x 480 px but the camera info '
        '(/camera/camera_info of'
    ),
    'calibration of another size': '00000.png: image is 640 x 480 px but the camera info',
    'unreadable video': 'clip.avi: OpenCV cannot open it as a video',
    'image folder with mixed sizes': ('00003.png: image is 320 x 240 px but the camera info ('),
    'timestamps file shorter than the video': 'stamps.txt has 4 stamps but',
    'no frames at all': 'frames: no image files',
    'video without --fps or --timestamps': (
        'clip.avi is a video without stamps: give --fps HZ or --timestamps FILE'
    ),
    'folder without --fps or --timestamps': 'frames is an image folder without stamps',
    'video without --camera-info': 'clip.avi has no camera_info: give --camera-info FILE',
    'bad --board': "--board '7x7': columns and rows must differ",
}


@pytest.mark.parametrize('case', sorted(BAD_INPUTS))
def test_bad_input_is_one_line_naming_it_and_exit_2(case, tmp_path, footage, capsys):
    src, options = _bad_source(case, tmp_path, footage)
    out = tmp_path / 'out'
    assert main(['track', str(src), str(out), *options]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith('lumpbeam track: error:') and len(err.splitlines()) == 1, err
    assert BAD_INPUTS[case] in err, err
    if case == 'unsupported distortion model':
        assert 'kannala_brandt_x' in err
    assert not out.exists()  # an incomplete OUT is not left behind
    print(f'\n{case}: {err}')


def test_a_corrupt_jpeg_in_a_bag_is_a_lost_frame_named_on_stderr(tmp_path, footage, capsys):
    info, frames = footage
    few = frames[:8]
    with BagWriter(tmp_path / 'in') as bag:
        for i, (frame, ns) in enumerate(zip(few, _stamps_ns(few), strict=True)):
            _, data = cv2.imencode('.jpg', frame.image)
            data = data.tobytes()[: len(data) // 2] if i == 5 else data.tobytes()
            msg = convert.compressed_image(ns, data, 'jpeg', 'camera')
            bag.write_message('/camera/image_raw/compressed', msg, ns)
    calibration = write_calibration(tmp_path / 'camera.yaml', info)
    out = tmp_path / 'out'
    assert main(['track', str(tmp_path / 'in'), str(out), '--camera-info', str(calibration)]) == 0
    printed = capsys.readouterr()
    assert '8 frames, 7 poses, 1 lost (bad_image 1)' in printed.out
    warning = printed.err.strip()
    assert len(warning.splitlines()) == 1 and warning.startswith('lumpbeam track: warning:')
    assert '/camera/image_raw/compressed message 5: corrupt JPEG' in warning
    print(f'\ncorrupt JPEG in a bag: {warning}')
    stamps = read_tip_poses(out).t
    assert len(stamps) == 7 and seconds_to_ns(few[5].stamp) / 1e9 not in stamps


@pytest.mark.parametrize('board', [None, ('6x4', '0.08')])
def test_the_board_comes_from_the_options(board, tmp_path, footage):
    """Footage of a 7 x 5-square board of 80 mm squares: found only when told so."""
    from dataclasses import replace

    from lumpbeam_ros.core.vision.config import with_board

    info, frames = footage
    config = with_board(load_camera_config().with_resolution(WIDTH, HEIGHT), (6, 4), 0.08)
    config = replace(config, camera_info=info)
    other = render_frames(config, drop_test_trajectory().between(START_S, 2.0), 8)
    src = _bag(tmp_path / 'in', other, 'mono8', info)
    options = [] if board is None else ['--board', board[0], '--square-m', board[1]]
    code = main(['track', str(src), str(tmp_path / 'out'), '--quiet', *options])
    if board is None:  # no 8 x 6 pattern there: no pose at all is an error, and no OUT
        assert code == 2 and not (tmp_path / 'out').exists()
    else:
        assert code == 0
        poses, error = _errors(tmp_path / 'out', other)
        assert len(poses.t) == 8 and np.max(np.abs(error[:, 1])) < 20e-6


class _Terminal(io.StringIO):
    def isatty(self):
        return True


@pytest.mark.parametrize('quiet', [False, True])
def test_a_progress_bar_on_a_terminal_unless_quiet(quiet, tmp_path, footage, monkeypatch):
    info, frames = footage
    src = _bag(tmp_path / 'in', frames[:10], 'mono8', info)
    terminal = _Terminal()
    monkeypatch.setattr(sys, 'stderr', terminal)
    options = ['--quiet'] if quiet else []
    assert main(['track', str(src), str(tmp_path / 'out'), *options]) == 0
    drawn = terminal.getvalue()
    if quiet:
        assert drawn == ''
    else:
        assert drawn.startswith('\rtracking [') and drawn.endswith('] 100%\n')
        assert drawn.count('\r') == 10  # one redraw per frame (10 % each)
