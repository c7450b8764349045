import numpy as np
import pytest

from lumpbeam_lab.camera.accuracy import drop_test_trajectory
from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.bagio import BagWriter, iter_images, read_camera_info, read_tip_poses
from lumpbeam_ros.core.model.parameters import BeamParameters, DropTestConfig
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, write_drop_test_bag
from lumpbeam_ros.core.synthetic.images import ImageOptions, ImageStream, parse_image_size
from lumpbeam_ros.core.vision.config import load_camera_config
from lumpbeam_ros.core.vision.messages import camera_info_from_data
from lumpbeam_ros.core.vision.synthetic import SyntheticCamera


@pytest.mark.parametrize(
    ('text', 'size'), [('2048x2048', (2048, 2048)), ('640X480', (640, 480)), (' 64x64 ', (64, 64))]
)
def test_image_size_parses(text, size):
    assert parse_image_size(text) == size


@pytest.mark.parametrize('text', ['', '640', '640x', 'x480', '640*480', '-640x480', '63x480'])
def test_bad_image_size_is_one_clear_error(text):
    with pytest.raises(LumpbeamError, match='--image-size'):
        parse_image_size(text)
    with pytest.raises(LumpbeamError):
        ImageOptions(32, 480)


def test_stream_writes_frames_with_their_camera_info_and_stops_at_the_end(tmp_path):
    trajectory = drop_test_trajectory().between(1.98, 2.01)  # 5 samples over the release
    options = ImageOptions(160, 120, seed=4)
    stream = ImageStream(trajectory, options)
    with BagWriter(tmp_path / 'bag') as bag:
        written = [stream.write_next(bag) for _ in range(len(trajectory))]
        with pytest.raises(LumpbeamError, match='all 5 frames'):
            stream.write_next(bag)
    frames = list(iter_images(tmp_path / 'bag'))
    assert [f.t for f in frames] == pytest.approx(list(trajectory.t), abs=1e-9)
    assert all(f.encoding == 'mono8' and f.frame_id == 'camera' for f in frames)
    # The bag holds exactly what the synthetic camera renders with that seed.
    config = load_camera_config().with_resolution(160, 120)
    expected = SyntheticCamera(config, seed=4).render_trajectory(
        trajectory.t, trajectory.x, trajectory.z, trajectory.pitch
    )
    for frame, again, mine in zip(frames, expected, written, strict=True):
        np.testing.assert_array_equal(frame.pixels, again.image)
        np.testing.assert_array_equal(mine.truth, again.truth)
    info = camera_info_from_data(read_camera_info(tmp_path / 'bag'))
    assert (info.width, info.height) == (160, 120)
    np.testing.assert_allclose(info.k, config.camera_info.k)


def test_drop_test_bag_films_the_measured_motion(tmp_path):
    """With a hidden latency, frames show the measured (late) motion at the pose stamps."""
    options = SynthOptions(duration_s=2.1, noise_m=0.0, effects={'sensor_latency': 0.01})
    measured, truth = write_drop_test_bag(
        tmp_path / 'bag', BeamParameters(), DropTestConfig(), options, images=ImageOptions(96, 72)
    )
    poses = read_tip_poses(tmp_path / 'bag')
    stamps = [f.t for f in iter_images(tmp_path / 'bag')]
    np.testing.assert_allclose(stamps, poses.t, atol=1e-9)
    assert len(stamps) == len(measured) == 379
    assert np.max(np.abs(measured.z - truth.z)) > 1e-4


def test_cli_writes_images_only_when_asked(tmp_path, capsys):
    assert main(['synth', str(tmp_path / 'a'), '--duration', '2.05']) == 0
    assert main(['synth', str(tmp_path / 'b'), '--duration', '2.05', '--images',
                 '--image-size', '80x64']) == 0  # fmt: skip
    out = capsys.readouterr().out
    assert '370 mono8 frames of 80x64 px' in out
    assert sum(1 for _ in iter_images(tmp_path / 'b')) == 370
    with pytest.raises(LumpbeamError, match='no topic /camera/image_raw'):
        next(iter_images(tmp_path / 'a'))
    assert main(['synth', str(tmp_path / 'c'), '--images', '--image-size', '8x8']) == 2
    assert 'at least 64 px' in capsys.readouterr().err
    assert not (tmp_path / 'c').exists()
