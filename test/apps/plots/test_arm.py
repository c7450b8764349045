"""The arm drawn from a bag's ``/beam_markers``: snapshots in the x-z plane, bad bags."""

import numpy as np
import pytest
from arm_cases import small_arm
from figures import color_rows, png_size
from matplotlib import colormaps

from lumpbeam_ros.apps.plots.arm import plot_arm_snapshots
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model.arm.joint_trajectory import JointTrajectory
from lumpbeam_ros.core.model.parameters import load_beam_config
from lumpbeam_ros.core.synthetic.arm_bag import ArmSynthOptions, write_arm_bag
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, write_drop_test_bag


def _viridis(fraction):
    return tuple(int(round(255 * c)) for c in colormaps['viridis'](fraction)[:3])


@pytest.fixture(scope='module')
def bag(tmp_path_factory):
    """A two-link arm moved for 0.2 s and left to ring for 0.3 s, with its markers."""
    path = tmp_path_factory.mktemp('arm') / 'arm'
    t = np.arange(0.0, 0.2 + 1e-9, 0.01)
    move = JointTrajectory(t, np.outer(t, [3.0, -3.0]))
    write_arm_bag(path, small_arm(2), move, ArmSynthOptions(duration_s=0.5))
    return path


def test_snapshots_of_the_arm_are_drawn(bag, tmp_path):
    path = plot_arm_snapshots(bag, tmp_path / 'figs' / 'arm.png', times=[0.0, 0.45])
    assert png_size(path) == (560, 560)  # 7 x 7 in at 80 dpi
    assert color_rows(path, _viridis(0.0)).size > 50  # the arm at rest, drawn
    assert color_rows(path, _viridis(0.9)).size > 50  # and after the move


def test_a_beam_bag_is_one_clear_error(tmp_path):
    beam, drop = load_beam_config()
    write_drop_test_bag(tmp_path / 'drop', beam, drop, SynthOptions(duration_s=2.1))
    with pytest.raises(LumpbeamError, match='no /beam_markers message draws an arm'):
        plot_arm_snapshots(tmp_path / 'drop', tmp_path / 'arm.png')
