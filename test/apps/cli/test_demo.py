import json
import math

import pytest
from demo_results import DURATION_S

from lumpbeam_ros.apps.cli.main import main


def test_demo_runs_the_graph_end_to_end(demo_results, mcap_doctor):
    assert demo_results.exit_code == 0, demo_results.printed
    out, printed = demo_results.out, demo_results.printed
    assert 'natural frequency (Hz)' in printed and 'demo finished' in printed
    summary = demo_results.summary
    assert json.loads((out.parent / 's.json').read_text()) == summary
    rows = summary['quantities']
    # The synthetic beam's first mode, identified from what the live graph recorded.
    assert rows['natural_frequency_hz']['identified'] == pytest.approx(3.0588, rel=2e-3)
    assert rows['natural_frequency_hz']['truth'] == pytest.approx(3.0588, rel=1e-3)
    assert rows['damping_ratio']['identified'] == pytest.approx(0.00237, rel=0.25)
    assert rows['stiffness_total_nm_per_rad']['identified'] == pytest.approx(3899.1, rel=0.02)
    assert rows['stiffness_total_nm_per_rad']['paper'] == 3899.1
    # The simulator predicted what the camera sees. The data hide a 15 ms camera latency: once
    # the live diagnosis has named it and the simulator adopted it during the replay, the
    # prediction is the 20 um noise from then on. Adopted at the replay's end (a slow
    # machine), the prediction before it is shifted by the one lag that aligns it best (the
    # latency; the simulator dates the unstamped /tip_load by when it was sent) and leaves a
    # few times the noise.
    live = summary['live_diagnosis']
    # Before the adoption (the whole record when none came), the hidden latency shows: over a
    # millimetre. Adopted early in the ring-down, the whole record's gap can fall below it.
    unadopted = live.get('prediction_before_rms_m') or summary['prediction_rms_m']
    assert abs(summary['prediction_lag_s']) < 0.1 and unadopted > 1e-3
    after = live.get('prediction_after_rms_m')
    # The node dates the release by the poses sent around /tip_load (up to one pose early):
    # the rest of the timing stays in the gap.
    late_s = live['window_s'][0] + 1.0 - 2.0  # pre_release_s before the 2 s release
    if after is None or not math.isfinite(after) or live.get('prediction_after_lag_s') is None:
        # Adopted at the replay's very end (too little after it to measure, or to align: a
        # lag needs 10 poses): the span before
        # the adoption is shifted by one lag. Over the whole record no one lag aligns both
        # sides of an adoption (seen in a run adopted 0.2 s before the end: 1.3 mm aligned
        # overall, 62 um before it).
        # Never adopted: the whole record is one span.
        before = live.get('prediction_before_aligned_rms_m', summary['prediction_rms_aligned_m'])
        assert before < 100e-6
    elif abs(late_s) <= 0.002:
        # The simulator dates the release on its own clock, which may be a /clock tick off:
        # that lag stays in both spans, and the adoption moved the prediction by the latency.
        shift_s = live['prediction_after_lag_s'] - live['prediction_before_lag_s']
        assert shift_s == pytest.approx(0.015, abs=0.002)
        assert (
            live['prediction_after_aligned_rms_m'] < 40e-6 < 1e-3 < live['prediction_before_rms_m']
        )
        if abs(live['prediction_after_lag_s']) < 0.001:
            assert after < 40e-6
    else:
        assert after < live['prediction_before_rms_m']
    samples = DURATION_S * 180 + 1
    assert summary['measured_samples'] == samples  # nothing lost by the recorder
    assert summary['predicted_samples'] > (DURATION_S - 1) * 180
    for name in ('tip_measured_vs_predicted.png', 'tip_release_zoom.png'):
        assert (out / 'figures' / name).stat().st_size > 10_000
    for name in ('simulator', 'recorder', 'player'):
        assert (out / 'logs' / f'{name}.log').stat().st_size > 0
    assert (out / 'bags' / 'recorded' / 'metadata.yaml').is_file()
    # Nothing lost in the live graph: every topic's publisher counted what it sent.
    counts = summary['topic_counts']
    assert counts['/tip_pose'] == {
        'publisher': 'player',
        'published': samples,
        'recorded': samples,
    }
    for topic, row in counts.items():
        assert row['published'] == row['recorded'] > 0, topic
    assert ['/tip_pose', 'player', str(samples), str(samples), '0'] in [
        ln.split() for ln in printed.splitlines()
    ]
    for bag in ('input', 'recorded', 'recorded_sim_time'):
        assert mcap_doctor(out / 'bags' / bag) == '', bag


@pytest.mark.parametrize(
    ('args', 'message'),
    [
        (['--duration', '2.5'], 'less than 1 s after the release'),
        (['--domain-id', '500'], '--domain-id must be in 1..101'),
        (['--config', '/no/such.yaml'], 'no such file'),
        (['--effect', 'gravity_wave=1'], 'unknown effect'),
        (['--effect', 'sensor_latency=-0.01'], 'latency_s must be in [0, 1]'),
        (['--image-size', '640by480'], 'expected WIDTHxHEIGHT'),
        (['--image-size', '8x8'], 'at least'),
    ],
)
def test_demo_refuses_bad_options(tmp_path, capsys, args, message):
    assert main(['demo', '--out', str(tmp_path / 'r'), *args]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize(
    ('args', 'message'),
    [
        (['--arm', 'config/paper_beam.yaml'], 'expected a mapping under the key arm'),
        (['--arm', '/no/such.yaml'], 'no such file'),
        (['--arm', '--effect', 'none'], '--effect is an option of the drop-test demo'),
        (['--arm', '--no-images'], '--no-images is an option of the drop-test demo'),
        (['--arm', '--domain-id', '500'], '--domain-id must be in 1..101'),
    ],
)
def test_arm_demo_refuses_bad_input(tmp_path, capsys, args, message):
    assert main(['demo', '--out', str(tmp_path / 'r'), *args]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / 'r' / 'bags').exists()  # refused before anything ran


def test_demo_never_deletes_a_folder_it_did_not_make(tmp_path, capsys):
    (tmp_path / 'bags' / 'mine').mkdir(parents=True)
    assert main(['demo', '--out', str(tmp_path)]) == 2
    assert 'was not made by lumpbeam demo' in capsys.readouterr().err
    assert (tmp_path / 'bags' / 'mine').is_dir()
    (tmp_path / 'file').write_text('x')
    assert main(['demo', '--out', str(tmp_path / 'file')]) == 2


def test_summary_table_reads_back_from_json():
    from lumpbeam_ros.apps.demo.summary import summary_lines

    row = {'identified': 3.0588, 'identified_std': 1e-6, 'live': None, 'truth': 3.0588}
    summary = {
        'quantities': {
            key: {**row, 'paper': 1.0}
            for key in ('natural_frequency_hz', 'damping_ratio', 'stiffness_total_nm_per_rad')
        },
        'prediction_rms_m': 2e-5,
        'prediction_rms_after_release_m': 2e-5,
        'prediction_max_m': 6e-5,
        'measured_samples': 10,
        'diagnosis': {'missing_effect': 'none'},
    }
    lines = summary_lines(summary)
    assert lines[1].split() == [
        *('natural', 'frequency', '(Hz)'),
        *('3.0588', '+-', '1e-06', '-', '3.0588', '1.0000'),
    ]
    assert 'RMS 0.020 mm' in lines[4] and lines[-1] == 'diagnosis: missing effect none'


# Best-effort camera frames: how many a machine tracks depends on its load (the bench measures
# it); the suite on a quiet machine (make test-slow, in CI) runs the whole camera path.
@pytest.mark.slow
@pytest.mark.ros
def test_demo_tracks_images_and_names_the_hidden_latency(tmp_path, capsys):
    # The default demo: camera frames through the camera node, and a 15 ms camera latency
    # hidden in the data for the diagnosis step.
    out = tmp_path / 'results'
    assert main(['demo', '--out', str(out), '--duration', '7']) == 0
    summary = json.loads((out / 'summary.json').read_text())
    assert summary['with_camera']
    # Images are best effort (the camera node may skip frames on a busy machine); every
    # pose it published is recorded.
    images = summary['image_counts']
    assert images['offered'] == 7 * 180 + 1 >= images['received'] >= images['tracked'] > 0
    poses = summary['topic_counts']['/tip_pose']
    assert poses['publisher'] == 'camera_node'
    assert poses['published'] == poses['recorded'] == images['tracked']
    assert summary['measured_samples'] == poses['recorded']
    rows = summary['quantities']
    assert rows['natural_frequency_hz']['identified'] == pytest.approx(3.0588, rel=2e-3)
    assert summary['camera_rms_m'] < 100e-6
    diagnosis = summary['diagnosis']
    assert diagnosis['missing_effect'] == 'sensor_latency'
    assert diagnosis['effect_parameters']['latency_s'] == pytest.approx(0.015, rel=0.25)
    assert diagnosis['gap_after']['rms_m'] < 0.3 * diagnosis['gap_before']['rms_m']
    assert (out / 'figures' / 'tip_tracked_vs_truth.png').stat().st_size > 10_000
    assert 'diagnosis: missing effect sensor_latency' in capsys.readouterr().out


def test_demo_names_the_hidden_latency_live_and_the_simulator_adopts_it(demo_results):
    assert demo_results.exit_code == 0, demo_results.printed
    live = demo_results.summary['live_diagnosis']
    printed = demo_results.printed
    assert 'live diagnosis (diagnosis_node, ring-down' in printed
    # Float64 /tip_load has no stamp: the diagnosis node dates the release by the poses sent
    # around it, and poses sent late (a busy machine: 5-20 ms) shift the latency it sees.
    late_s = live['window_s'][0] + 1.0 - 2.0  # pre_release_s before the 2 s release
    if abs(late_s) > 0.002:
        # Then the latency it sees is shorter than the hidden one: a smaller latency, or no
        # confident answer, but never another effect's name.
        assert live['missing_effect'] in ('sensor_latency', 'unexplained', 'none'), late_s
        return
    assert live['missing_effects'] == ['sensor_latency'] and live['level'] == 1
    assert live['window_s'][1] - live['window_s'][0] == pytest.approx(3.3, abs=0.05)
    assert live['gap_after_rms_m'] < 0.1 * live['gap_before_rms_m']
    # The simulator accepted it through its parameter service (whenever the worker finished).
    assert live['adoption'].startswith('adopted by simulator_node: effects.sensor_latency')
    assert 'adoption: adopted by simulator_node' in printed


def test_the_two_demos_write_to_folders_of_their_own():
    from pathlib import Path

    from lumpbeam_ros.apps.cli.demo import output_folder

    assert output_folder(None, arm=False) == Path('results')
    assert output_folder(None, arm=True) == Path('results/arm')
    assert output_folder(Path('elsewhere'), arm=True) == Path('elsewhere')
