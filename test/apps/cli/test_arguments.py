import argparse

import pytest

from lumpbeam_ros.apps.cli import arguments
from lumpbeam_ros.apps.cli.main import build_parser
from lumpbeam_ros.core.compare import bag_comparison as compare_bag
from lumpbeam_ros.core.synthetic.reference_sensor import ReferenceSensorOptions
from lumpbeam_ros.core.vision import offline

TRACKER = ReferenceSensorOptions()


@pytest.mark.parametrize(
    ('command', 'option', 'core'),
    [
        # None: the raw images, else the compressed ones, else the bag's only image topic.
        (['track', 'in', 'out'], 'image_topic', None),
        (['track', 'in', 'out'], 'camera_info_topic', offline.CAMERA_INFO_TOPIC),
        (['compare', 'bag'], 'camera_topic', compare_bag.CAMERA_TOPIC),
        (['compare', 'bag'], 'reference_topic', compare_bag.REFERENCE_TOPIC),
        (['synth', 'out'], 'tracker_rate', TRACKER.rate_hz),
        (['synth', 'out'], 'tracker_noise', TRACKER.noise_m),
        (['synth', 'out'], 'tracker_offset', TRACKER.clock_offset_s),
        (['synth', 'out'], 'tracker_pose', (*TRACKER.position_m, *TRACKER.rotation_deg)),
        (['synth', 'out'], 'tracker_lever', TRACKER.lever_m),
    ],
)
def test_defaults_are_the_cores(command, option, core):
    assert getattr(build_parser().parse_args(command), option) == core


def test_tracker_pose_reads_six_numbers():
    assert arguments.tracker_pose('1,2,3,4,5,6') == (1.0, 2.0, 3.0, 4.0, 5.0, 6.0)


@pytest.mark.parametrize('text', ['1,2,3', '1,2,3,4,5,x', ''])
def test_tracker_pose_rejects_anything_else(text):
    with pytest.raises(argparse.ArgumentTypeError):
        arguments.tracker_pose(text)


def test_a_bad_tracker_pose_is_a_usage_error(capsys):
    with pytest.raises(SystemExit) as exit_:
        build_parser().parse_args(['synth', 'out', '--tracker-pose', '1,2'])
    assert exit_.value.code == 2
    assert "expected 6 comma-separated numbers, got '1,2'" in capsys.readouterr().err


@pytest.mark.parametrize('command', [['analyze', 'bag'], ['diagnose', 'bag'], ['compare', 'bag']])
@pytest.mark.parametrize('name', ['report.html', 'out/Report.HTM'])
def test_report_takes_an_html_file(command, name):
    assert build_parser().parse_args([*command, '--report', name]).report == name


@pytest.mark.parametrize('command', [['analyze', 'bag'], ['diagnose', 'bag'], ['compare', 'bag']])
@pytest.mark.parametrize('name', ['report.txt', 'report', 'html'])
def test_a_report_that_is_not_html_is_refused_before_any_work(command, name, capsys):
    with pytest.raises(SystemExit) as exit_:
        build_parser().parse_args([*command, '--report', name])
    assert exit_.value.code == 2
    assert f"the report is an HTML file (FILE.html), not '{name}'" in capsys.readouterr().err


def test_shaper_choices_are_the_cores():
    from lumpbeam_ros.core.shaping.shapers import SHAPERS

    assert arguments.SHAPER_NAMES == tuple(SHAPERS)
