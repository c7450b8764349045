import json

import numpy as np
import pytest

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.core.bagio import BagReader, BagWriter, iter_images, read_tip_poses
from lumpbeam_ros.core.model.parameters import load_beam_config
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, write_drop_test_bag
from lumpbeam_ros.core.synthetic.images import ImageOptions


@pytest.fixture(scope='module')
def bag(tmp_path_factory):
    """A 2.3 s synthetic drop test filmed at 320 x 240 (415 frames, 0.3 s of motion)."""
    path = tmp_path_factory.mktemp('track') / 'in'
    beam, drop = load_beam_config()
    write_drop_test_bag(
        path, beam, drop, SynthOptions(duration_s=2.3), images=ImageOptions(320, 240)
    )
    return path


@pytest.mark.parametrize('keep_images', [False, True], ids=['default', 'keep-images'])
def test_out_is_the_bag_plus_tracked_poses(bag, tmp_path, capsys, keep_images):
    out = tmp_path / 'out'
    options = ['--json', str(tmp_path / 'r.json')] + ['--keep-images'] * keep_images
    assert main(['track', str(bag), str(out), *options]) == 0
    text = capsys.readouterr().out
    assert 'tracked' in text and '415 frames, 415 poses, 0 lost' in text
    assert '/tip_pose of' in text and '(415 poses) replaced' in text
    original, copy = BagReader(bag), BagReader(out)
    left_out = set() if keep_images else {'/camera/image_raw'}
    assert set(copy.topics) == set(original.topics) - left_out
    assert ('--keep-images keeps them): /camera/image_raw' in text) is not keep_images
    for name in copy.topics:
        assert copy.topics[name].count == original.topics[name].count
        assert copy.topics[name].qos == original.topics[name].qos
    for topic in {'/camera/image_raw', '/tip_load'} - left_out:
        before = [bytes(m.data) for m in original.iter_raw([topic])]
        after = [bytes(m.data) for m in copy.iter_raw([topic])]
        assert before == after
    tracked, noisy = read_tip_poses(out), read_tip_poses(bag)
    truth = read_tip_poses(out, '/tip_pose_truth')
    np.testing.assert_array_equal(tracked.t, [f.t for f in iter_images(bag)])
    assert tracked.frame_id == 'beam_base'
    # The tracked poses replaced the bag's noisy ones: they sit on the truth.
    assert np.max(np.abs(noisy.z - tracked.z)) > 40e-6
    assert np.sqrt(np.mean((tracked.z - truth.z) ** 2)) < 30e-6
    result = json.loads((tmp_path / 'r.json').read_text())
    assert result['frames'] == result['poses'] == 415 and result['lost'] == 0
    assert result['replaced_poses'] == 415 and result['fps'] > 0
    assert result['images_left_out'] == sorted(left_out)
    assert 0 < result['z_rms_um'] < 30
    assert f'z rms {result["z_rms_um"]:.2f} um' in text


def test_a_corrupt_frame_is_lost_not_fatal(bag, tmp_path, capsys):
    cut = tmp_path / 'cut'
    with BagWriter(cut) as writer:
        reader = BagReader(bag)
        for name in ('/camera/image_raw', '/camera/camera_info'):
            writer.add_topic(name, reader.topics[name].msgtype)
        raws = reader.iter_raw(['/camera/image_raw', '/camera/camera_info'])
        for i, raw in enumerate(raws):
            if i >= 40:
                break
            data = b'\x00\x01\x00\x00\xff' if i == 21 else raw.data
            writer.write_raw(raw.topic, raw.log_time_ns, data)
    assert main(['track', str(cut), str(tmp_path / 'out')]) == 0
    text = capsys.readouterr().out
    assert '20 frames, 19 poses, 1 lost (bad_image 1)' in text
    assert 'replaced' not in text and 'truth' not in text
    assert len(read_tip_poses(tmp_path / 'out').t) == 19


@pytest.mark.parametrize('case', ['not a bag', 'no images', 'no camera info', 'out exists'])
def test_bad_input_is_one_line_and_exit_2(bag, tmp_path, capsys, case):
    source, out = bag, tmp_path / 'out'
    if case == 'not a bag':
        source = tmp_path / 'plain'
        source.mkdir()
        (source / 'notes.txt').write_text('hello')
    elif case == 'no images':
        source = tmp_path / 'poses'
        beam, drop = load_beam_config()
        write_drop_test_bag(source, beam, drop, SynthOptions(duration_s=2.05))
    elif case == 'no camera info':
        source = tmp_path / 'images'
        with BagWriter(source) as writer:
            writer.write_image('/camera/image_raw', 1.0, np.zeros((64, 64), np.uint8))
    else:
        out.mkdir()
    assert main(['track', str(source), str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith('lumpbeam track: error:') and len(err.splitlines()) == 1
    expected = {
        'not a bag': 'plain',
        'no images': 'no topic /camera/image_raw',
        'no camera info': 'no topic /camera/camera_info',
        'out exists': 'exists already',
    }[case]
    assert expected in err


def test_free_pose_model_writes_full_poses(bag, tmp_path, capsys):
    out = tmp_path / 'free'
    assert main(['track', str(bag), str(out), '--pose-model', 'free']) == 0
    assert '415 frames, 415 poses, 0 lost' in capsys.readouterr().out
    tracked, truth = read_tip_poses(out), read_tip_poses(out, '/tip_pose_truth')
    # 6 DoF from a flat board at 320 x 240 are loose, but on the truth to a fraction of a mm.
    assert np.sqrt(np.mean((tracked.z - truth.z) ** 2)) < 1e-3
    assert np.sqrt(np.mean((tracked.pitch - truth.pitch) ** 2)) < 3e-3
    messages = BagReader(out).messages('/tip_pose', 'geometry_msgs/msg/PoseStamped')
    ys = [m.pose.position.y for _, m in messages]
    assert np.max(np.abs(ys)) > 0 and np.max(np.abs(ys)) < 5e-3


def test_unknown_pose_model_is_exit_2(bag, tmp_path, capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(['track', str(bag), str(tmp_path / 'o'), '--pose-model', 'bent'])
    assert exit_info.value.code == 2
    err = capsys.readouterr().err
    assert '--pose-model' in err and 'bent' in err


def test_out_draws_the_tracked_tip_and_the_board(bag, tmp_path, capsys):
    from lumpbeam_ros.core.viz.marker_messages import read_marker_arrays

    out = tmp_path / 'out'
    assert main(['track', str(bag), str(out)]) == 0
    tracked = read_tip_poses(out)
    arrays = list(read_marker_arrays(out))
    # At most 30 Hz of the 180 Hz poses; the bag's own markers (the synthetic truth's beam)
    # are replaced, not mixed in.
    assert 0.9 * 30 * 2.3 <= len(arrays) <= 30 * 2.3 + 1
    for t, markers in arrays:
        by_ns = {m.namespace: m for m in markers}
        assert {'tip_measured', 'board'} <= set(by_ns) and 'beam' not in by_ns
        i = int(np.argmin(np.abs(tracked.t - t)))
        assert tracked.t[i] == pytest.approx(t, abs=1e-9)  # drawn at a tracked pose's stamp
        tip = by_ns['tip_measured'].position
        assert (tip[0], tip[2]) == pytest.approx((tracked.x[i], tracked.z[i]), abs=1e-12)
        assert by_ns['board'].position == pytest.approx((2.3107, 1.0, -0.01))


def test_no_pose_in_any_frame_is_an_error_without_out(bag, tmp_path, capsys):
    """Every frame black: the board is never found. No OUT without a /tip_pose."""
    dark = tmp_path / 'dark'
    with BagWriter(dark) as writer:
        reader = BagReader(bag)
        writer.add_topic('/camera/camera_info', reader.topics['/camera/camera_info'].msgtype)
        for raw in reader.iter_raw(['/camera/camera_info']):
            writer.write_raw(raw.topic, raw.log_time_ns, raw.data)
        for i in range(12):
            writer.write_image('/camera/image_raw', 10.0 + i / 30, np.zeros((240, 320), np.uint8))
    out = tmp_path / 'out'
    assert main(['track', str(dark), str(out), '--json', str(tmp_path / 'r.json')]) == 2
    printed = capsys.readouterr()
    assert printed.out == ''
    err = printed.err.strip()
    assert err.startswith('lumpbeam track: error:') and len(err.splitlines()) == 1
    assert f'{dark}: no pose in any of its 12 frames (' in err and 'first:' in err
    assert not out.exists() and not (tmp_path / 'r.json').exists()


def test_force_replaces_the_output_never_the_source(tmp_path, capsys):
    from lumpbeam_ros.apps.cli.main import main as lumpbeam

    src = tmp_path / 'src'
    assert lumpbeam(['synth', str(src), '--duration', '3']) == 0
    capsys.readouterr()
    assert lumpbeam(['track', str(src), str(src), '--force']) == 2
    assert 'would replace the source' in capsys.readouterr().err
    assert (src / 'metadata.yaml').is_file()
