"""Every kind of bag the product writes passes the MCAP check (`core.bagio.check`) cleanly.

The live kinds are checked where they are made: a recording in test/apps/cli/test_record.py, the
demo's recorded and sim-time bags in test/apps/cli/test_demo.py, a sim-time copy in
test/apps/demo/test_recording.py, a repaired bag in test/apps/cli/test_repair.py.
"""

import pytest

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.core.model.parameters import load_beam_config
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, write_drop_test_bag
from lumpbeam_ros.core.synthetic.images import ImageOptions


@pytest.fixture(scope='module')
def filmed(tmp_path_factory):
    """A 2.2 s synthetic drop test with 320 x 240 camera frames."""
    path = tmp_path_factory.mktemp('doctor') / 'filmed'
    beam, drop = load_beam_config()
    write_drop_test_bag(
        path, beam, drop, SynthOptions(duration_s=2.2), images=ImageOptions(320, 240)
    )
    return path


def test_a_synthetic_bag_is_clean(tmp_path, mcap_doctor):
    assert main(['synth', str(tmp_path / 'synth'), '--duration', '3', '--tracker']) == 0
    assert mcap_doctor(tmp_path / 'synth') == ''


def test_a_synthetic_bag_with_images_is_clean(filmed, mcap_doctor):
    assert mcap_doctor(filmed) == ''


def test_a_tracked_bag_is_clean(filmed, tmp_path, mcap_doctor):
    assert main(['track', str(filmed), str(tmp_path / 'tracked')]) == 0
    assert mcap_doctor(tmp_path / 'tracked') == ''


def test_the_doctor_does_flag_a_bag_out_of_order(tmp_path, mcap_doctor):
    # The check can fail: rosbags' writer, fed out of order, makes what the doctor flags.
    from rosbags.rosbag2 import StoragePlugin, Writer

    from lumpbeam_ros.core.bagio import convert
    from lumpbeam_ros.core.bagio.typestore import serialize, type_description

    msgdef, rihs01 = type_description('std_msgs/msg/Float64')
    with Writer(tmp_path / 'raw', version=9, storage_plugin=StoragePlugin.MCAP) as writer:
        connection = writer.add_connection(
            '/a', 'std_msgs/msg/Float64', msgdef=msgdef, rihs01=rihs01
        )
        for ns in (2, 1):
            writer.write(connection, ns, serialize(convert.float64(0.0)))
    assert 'less than the latest log time' in mcap_doctor(tmp_path / 'raw')
