"""A short soak of the live graph on a looping bag: every pass diagnosed as offline."""

import pytest

from lumpbeam_lab.graph.soak import soak


@pytest.mark.slow
@pytest.mark.ros
def test_a_looping_bag_on_wall_time_is_diagnosed_every_pass_as_offline(tmp_path, capsys):
    assert soak(1.5, 12.0, sim_time=False, folder=tmp_path) == 0, capsys.readouterr().out
    printed = capsys.readouterr().out
    assert 'result                          pass' in printed
