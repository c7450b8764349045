"""The camera against the tracker (Fig. B.8): the file, its size, each trace in its panel."""

import pytest
from core.compare.helpers import make_pair
from figures import color_rows, png_size

from lumpbeam_ros.apps.plots.comparison import FILE_NAME, plot_comparison
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.compare.comparison import compare_sensors
from lumpbeam_ros.core.model.parameters import BeamParameters

#: matplotlib's tab: colours, as the traces are drawn.
TRACKER = (255, 127, 14)  # tab:orange
CAMERA = (31, 119, 180)  # tab:blue
DIFFERENCE = (214, 39, 40)  # tab:red


@pytest.fixture(scope='module')
def comparison():
    pair = make_pair(duration=4.0)
    return compare_sensors(pair.camera, pair.reference, BeamParameters(), pair.loads)


@pytest.fixture(scope='module')
def figure(comparison, tmp_path_factory):
    return plot_comparison(comparison, tmp_path_factory.mktemp('plots') / 'new' / 'folder')


def test_the_figure_is_a_png_in_a_created_folder(figure):
    assert figure.name == FILE_NAME and figure.parent.name == 'folder'
    assert png_size(figure) == (990, 660)  # 9 x 6 in at 110 dpi


@pytest.mark.parametrize(
    ('color', 'panel', 'least'),
    # The thin camera trace covers the tracker's (they agree to microns): the tracker shows
    # in the legend and at the end, where the camera's record stops first.
    [(TRACKER, 'top', 40), (CAMERA, 'top', 500), (DIFFERENCE, 'bottom', 500)],
    ids=['tracker', 'camera', 'difference'],
)
def test_each_trace_is_drawn_in_its_panel(figure, color, panel, least):
    rows = color_rows(figure, color)
    assert rows.size > least
    inside = (rows < 0.5) if panel == 'top' else (rows > 0.5)
    assert inside.mean() > 0.99


def test_writing_again_replaces_the_file(comparison, figure):
    before = figure.stat().st_size
    assert plot_comparison(comparison, figure.parent) == figure
    assert figure.stat().st_size == pytest.approx(before, rel=0.01)
    assert sorted(p.name for p in figure.parent.iterdir()) == [FILE_NAME]


def test_an_unwritable_folder_is_one_clear_error(comparison, tmp_path):
    blocker = tmp_path / 'file'
    blocker.write_text('')
    with pytest.raises(LumpbeamError, match='cannot write the plot') as info:
        plot_comparison(comparison, blocker / 'plots')
    assert '\n' not in str(info.value)
