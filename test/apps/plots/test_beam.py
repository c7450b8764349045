"""The beam drawn from a bag's ``/beam_markers``: snapshots chosen, file written, bad bags."""

import numpy as np
import pytest
from figures import color_rows, png_size
from matplotlib import colormaps

from lumpbeam_ros.apps.plots.beam import drop_snapshot_times, plot_beam_snapshots, snapshot_indices
from lumpbeam_ros.base.errors import BagError, LumpbeamError
from lumpbeam_ros.core.bagio import BagWriter
from lumpbeam_ros.core.model.parameters import load_beam_config
from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, write_drop_test_bag
from lumpbeam_ros.core.viz.marker_messages import write_scene
from lumpbeam_ros.core.viz.markers import BeamScene, TipPoint

STAMPS = np.arange(10) * 0.1  # 0.0 .. 0.9 s


def _viridis(fraction):
    return tuple(int(round(255 * c)) for c in colormaps['viridis'](fraction)[:3])


#: The first and the last snapshot's colours (plot_beam_snapshots spreads 0 .. 0.9).
FIRST, LAST = _viridis(0.0), _viridis(0.9)


@pytest.fixture(scope='module')
def bag(tmp_path_factory):
    """3 s of the drop test (released at 2 s) with its markers at 30 Hz."""
    path = tmp_path_factory.mktemp('beam') / 'drop'
    beam, drop = load_beam_config()
    write_drop_test_bag(path, beam, drop, SynthOptions(duration_s=3.0))
    return path


@pytest.mark.parametrize(
    ('times', 'count', 'expected'),
    [
        (None, 4, [0, 3, 6, 9]),
        (None, 1, [0]),
        (None, 20, list(range(10))),
        ([0.31], 6, [3]),
        ([0.5, 0.12, 0.5, 0.49], 6, [1, 5]),
        ([-5.0, 42.0], 6, [0, 9]),
        ([], 6, []),
    ],
    ids=['spread-4', 'spread-1', 'more-than-stamps', 'one', 'sorted-distinct', 'clamped', 'none'],
)
def test_snapshot_indices(times, count, expected):
    assert snapshot_indices(STAMPS, times, count) == expected


@pytest.mark.parametrize(
    ('release', 'period', 'expected'),
    [
        (2.0, 0.4, [1.5, 2.0, 2.1, 2.2, 2.3, 2.4]),
        (10.0, 1.0 / 3.06, [9.5] + [10.0 + k / (4 * 3.06) for k in range(5)]),
    ],
)
def test_drop_snapshot_times_rest_then_quarter_periods(release, period, expected):
    assert drop_snapshot_times(release, period) == pytest.approx(expected)


def test_the_default_draws_six_instants(bag, tmp_path):
    path = plot_beam_snapshots(bag, tmp_path / 'figs' / 'beam.png', release_time_s=2.0)
    assert path == tmp_path / 'figs' / 'beam.png'
    assert png_size(path) == (990, 770)  # 9 x 7 in at 110 dpi
    # The last instant is drawn on top; the first (at rest, under the later rest shapes)
    # shows in the legend and as its dotted line in the lower panel.
    assert color_rows(path, LAST).size > 100
    assert np.any(color_rows(path, FIRST) > 0.6)


def test_one_instant_draws_one_colour(bag, tmp_path):
    path = plot_beam_snapshots(bag, tmp_path / 'one.png', times=[2.2], title='one')
    assert png_size(path) == (990, 770)
    assert color_rows(path, FIRST).size > 100
    assert color_rows(path, LAST).size == 0


def test_a_bag_without_markers_is_a_bag_error(tmp_path):
    with BagWriter(tmp_path / 'poses') as writer:
        writer.write_pose('/tip_pose', 1.0, 2.3, -0.05, 0.02)
    with pytest.raises(BagError, match='/beam_markers'):
        plot_beam_snapshots(tmp_path / 'poses', tmp_path / 'beam.png')
    assert not (tmp_path / 'beam.png').exists()


def test_markers_without_a_beam_are_one_clear_error(tmp_path):
    # What `lumpbeam track` writes: the measured tip only, no model shape.
    with BagWriter(tmp_path / 'tracked') as writer:
        for i in range(3):
            write_scene(writer, 0.1 * i, BeamScene(0.0, measured=TipPoint(2.3, -0.05)), 0.1)
    with pytest.raises(LumpbeamError, match='no /beam_markers message draws the beam'):
        plot_beam_snapshots(tmp_path / 'tracked', tmp_path / 'beam.png')


def test_an_unwritable_path_is_one_clear_error(bag, tmp_path):
    blocker = tmp_path / 'file'
    blocker.write_text('')
    with pytest.raises(LumpbeamError, match='cannot write') as info:
        plot_beam_snapshots(bag, blocker / 'beam.png')
    assert '\n' not in str(info.value)
