import json
import math
import re

import numpy as np
import pytest

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.core.bagio import BagWriter, read_points, read_tip_poses


@pytest.fixture(scope='module')
def tracker_bag(tmp_path_factory):
    """A 5 s synthetic drop test with the default tracker (7.3 ms, 15 um, 3 m away)."""
    bag = tmp_path_factory.mktemp('compare') / 'drop'
    assert main(['synth', str(bag), '--duration', '5', '--tracker']) == 0
    return bag


def _one_line_error(capsys, argv, *phrases):
    assert main(argv) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert len(lines) == 1, captured.err
    assert lines[0].startswith('lumpbeam compare: error: ')
    for phrase in phrases:
        assert phrase in lines[0]
    return lines[0]


def test_compare_prints_json_and_plot(tracker_bag, tmp_path, capsys):
    out, plots = tmp_path / 'c.json', tmp_path / 'plots'
    assert main(['compare', str(tracker_bag), '--json', str(out), '--plots', str(plots)]) == 0
    printed = capsys.readouterr().out
    assert re.search(r'tracker_stamp = camera_stamp \+ 7\.(29|30)\d+ \+- 0\.00\d+ ms', printed)
    assert 'natural frequency [Hz]' in printed
    data = json.loads(out.read_text())
    assert data['time_offset_s'] == pytest.approx(7.3e-3, abs=0.2e-3)
    assert 0.0 < data['time_offset_s_std'] < 1e-4
    assert data['rms_difference_m'] < 1.5 * math.hypot(20e-6, 15e-6)
    assert data['max_difference_m'] > data['rms_difference_m']
    camera, tracker = data['per_sensor']['camera'], data['per_sensor']['tracker']
    assert camera['status'] == tracker['status'] == 'OK'
    assert tracker['natural_frequency_hz'] == pytest.approx(
        camera['natural_frequency_hz'], rel=1e-3
    )
    assert tracker['damping_ratio'] == pytest.approx(camera['damping_ratio'], rel=0.05)
    assert (plots / 'compare.png').stat().st_size > 10_000


def test_dropouts_in_a_bag(tmp_path, capsys):
    # Copy the streams of a short synthetic bag, with 40 ms tracker dropouts every second.
    source, bag = tmp_path / 'source', tmp_path / 'gappy'
    assert main(['synth', str(source), '--duration', '4', '--tracker']) == 0
    poses, points = read_tip_poses(source), read_points(source)
    lost = (points.t % 1.0 > 0.5) & (points.t % 1.0 < 0.54)
    with BagWriter(bag) as writer:
        for t, x, z, pitch in zip(poses.t, poses.x, poses.z, poses.pitch, strict=True):
            writer.write_pose('/tip_pose', t, x, z, pitch)
        for t, x, y, z in zip(*(a[~lost] for a in points[:4]), strict=True):
            writer.write_point('/tracker/point', t, x, y, z, points.frame_id)
    capsys.readouterr()
    out = tmp_path / 'c.json'
    assert main(['compare', str(bag), '--json', str(out)]) == 0
    assert '4 gaps' in capsys.readouterr().out
    data = json.loads(out.read_text())
    assert data['reference_gaps'] == 4
    assert data['time_offset_s'] == pytest.approx(7.3e-3, abs=0.2e-3)
    assert data['pairs'] < poses.t.size - 4 * 6
    # No /tip_load: the release is found in the data.
    assert data['per_sensor']['tracker']['release_source'] == 'data'


def test_only_the_camera(tmp_path, capsys):
    bag = tmp_path / 'camera_only'
    assert main(['synth', str(bag), '--duration', '3']) == 0
    capsys.readouterr()
    _one_line_error(capsys, ['compare', str(bag)], 'no reference sensor (/tracker/point)')


def test_streams_that_never_overlap(tmp_path, capsys):
    bag = tmp_path / 'late'
    assert main(['synth', str(bag), '--duration', '3', '--tracker', '--tracker-offset', '40']) == 0
    capsys.readouterr()
    _one_line_error(capsys, ['compare', str(bag)], 'never overlap', '--max-offset')


@pytest.mark.parametrize(
    ('points', 'phrase'),
    [
        ('identical', 'the points do not move'),
        ('line', 'lie on a line'),
    ],
)
def test_a_frame_that_cannot_be_aligned(tmp_path, capsys, points, phrase):
    source, bag = tmp_path / 'source', tmp_path / points
    assert main(['synth', str(source), '--duration', '3']) == 0
    poses = read_tip_poses(source)
    t = np.arange(0.0, 3.0, 1e-3)
    z = np.interp(t, poses.t, poses.z)
    rng = np.random.default_rng(0)
    with BagWriter(bag) as writer:
        for ti, x, z_i, pitch in zip(poses.t, poses.x, poses.z, poses.pitch, strict=True):
            writer.write_pose('/tip_pose', ti, x, z_i, pitch)
        for ti, zi in zip(t, z, strict=True):
            if points == 'identical':
                p = (1.0, 2.0, 3.0)
            else:
                p = (0.6 * zi, 0.8 * zi, 1.0) + 15e-6 * rng.standard_normal(3)
            writer.write_point('/tracker/point', ti, *p, 'tracker')
    capsys.readouterr()
    _one_line_error(capsys, ['compare', str(bag)], phrase)


def test_missing_bag(tmp_path, capsys):
    _one_line_error(capsys, ['compare', str(tmp_path / 'nothing')], 'nothing')
