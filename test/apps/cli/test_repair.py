import numpy as np
import pytest
from core.bagio.helpers import write_drop_bag

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.core.bagio import BagReader, read_tip_poses


@pytest.fixture
def cut(tmp_path):
    """A bag whose data file ends mid-record, as a killed writer leaves it."""
    write_drop_bag(tmp_path / 'cut')
    data_file = next((tmp_path / 'cut').glob('*.mcap'))
    data_file.write_bytes(data_file.read_bytes()[: data_file.stat().st_size * 2 // 3])
    return tmp_path / 'cut'


def test_a_cut_bag_is_copied_whole_with_exact_counts(cut, tmp_path, capsys, mcap_doctor):
    readable = read_tip_poses(cut)
    assert main(['repair', str(cut), str(tmp_path / 'whole')]) == 0
    printed = capsys.readouterr().out
    assert f'into {tmp_path / "whole"}' in printed and 'warning: /tip_pose: kept' in printed
    whole = BagReader(tmp_path / 'whole')
    assert not whole.truncated
    assert whole.topics['/tip_pose'].count == readable.t.size
    assert whole.topics['/tip_pose'].qos == BagReader(cut).topics['/tip_pose'].qos
    np.testing.assert_array_equal(read_tip_poses(whole).z, readable.z)
    assert mcap_doctor(tmp_path / 'whole') == ''


@pytest.mark.parametrize(
    ('args', 'match'),
    [
        (['{tmp}/missing'], 'no such bag'),
        (['{cut}', '{cut}'], 'exists already'),
    ],
)
def test_bad_input_is_one_line_and_exit_2(cut, tmp_path, capsys, args, match):
    argv = ['repair', *(a.format(tmp=tmp_path, cut=cut) for a in args)]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith('lumpbeam repair: error:') and match in err
    assert len(err.splitlines()) == 1
