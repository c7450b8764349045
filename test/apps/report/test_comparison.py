"""``lumpbeam compare --report``: a camera and a laser tracker compared, the page read back."""

import math

import numpy as np
import pytest
from core.compare.helpers import CAMERA_NOISE, TRACKER_NOISE, make_pair
from figures import png_size

from lumpbeam_ros.apps.report.comparison import difference_figure, write_comparison_report
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.compare.comparison import compare_sensors
from lumpbeam_ros.core.ident.bag_analysis import CONTRACT_KEYS
from lumpbeam_ros.core.model.parameters import BeamParameters

from .helpers import parse_page


@pytest.fixture(scope='module')
def pair():
    return make_pair(duration=4.0)


@pytest.fixture(scope='module')
def comparison(pair):
    return compare_sensors(pair.camera, pair.reference, BeamParameters(), pair.loads)


@pytest.fixture(scope='module')
def page(comparison, tmp_path_factory):
    path = tmp_path_factory.mktemp('page') / 'compare.html'
    assert write_comparison_report(comparison, '/bags/tracked', path) == path
    return parse_page(path.read_text(encoding='utf-8'))


def test_the_page_names_the_bag_and_counts(comparison, page):
    assert page.title == 'lumpbeam compare: tracked'
    data = comparison.as_dict()
    assert page.paragraphs == [
        (
            f'/bags/tracked: {data["pairs"]} pairs, {data["reference_samples"]} reference samples',
            None,
        )
    ]
    assert page.h2 == [
        'Alignment (1 sigma)',
        'Difference after alignment (camera - tracker)',
        'Identification from each sensor (1 sigma)',
    ]


def test_the_alignment_recovers_the_tracker_clock_and_place(pair, page):
    table = page.table_dict(0)
    offset, offset_std = table['time offset, s (tracker = camera + offset)']
    assert float(offset) == pytest.approx(pair.tracker.clock_offset_s, abs=1e-4)
    assert 0.0 < float(offset_std) < 1e-4
    assert table['coarse offset, s (cross-correlation)'][1] == 'n/a'
    translation = [[float(v) for v in table[f'translation {a}, m']] for a in 'xyz']
    # A planar swing pins the tracker's place to millimetres (as test/core/compare checks it).
    np.testing.assert_allclose([v for v, _ in translation], pair.tracker.position_m, atol=0.02)
    assert all(std > 0.0 for _, std in translation)
    for axis in 'xyz':
        value, std = table[f'rotation about {axis}, rad (std)']
        assert value == 'n/a' and 0.0 < float(std) < 1e-2
    assert float(table['off-plane RMS, m'][0]) < 3 * TRACKER_NOISE


def test_the_difference_is_at_the_noise_level(comparison, page):
    table = page.table_dict(1)
    rms_z = float(table['RMS (z)'][0])
    assert rms_z == pytest.approx(comparison.rms_difference_m, rel=1e-4)
    assert 0.7 * CAMERA_NOISE < rms_z < 1.5 * math.hypot(CAMERA_NOISE, TRACKER_NOISE)
    assert float(table['max (z)'][0]) > rms_z
    header, *rows = page.tables[1]
    assert header == ['figure', 'value, m']
    assert [row[0] for row in rows] == ['RMS (z)', 'max (z)', 'RMS (x)', 'RMS (y)', 'RMS (z)']
    assert rows[0][1] == rows[-1][1]  # the headline and the per-axis z are the same figure


def test_both_sensors_identify_the_same_beam(page):
    header, *rows = page.tables[2]
    assert header == ['estimate', 'camera', 'camera std', 'tracker', 'tracker std']
    assert [row[0] for row in rows] == list(CONTRACT_KEYS)
    table = page.table_dict(2)
    camera, camera_std, tracker, tracker_std = (float(v) for v in table['natural_frequency_hz'])
    assert camera == pytest.approx(3.06, rel=0.02)
    assert abs(camera - tracker) < 5 * math.hypot(camera_std, tracker_std)


def test_both_figures_are_pngs_of_their_size(page):
    assert [alt for alt, _ in page.images] == ['residual camera - tracker', 'compare']
    assert [png_size(data) for _, data in page.images] == [(990, 660), (990, 660)]


def test_the_difference_figure_alone(comparison):
    assert png_size(difference_figure(comparison)) == (990, 660)


def test_a_path_that_is_not_html_is_refused(comparison, tmp_path):
    with pytest.raises(LumpbeamError, match='the report is an HTML file'):
        write_comparison_report(comparison, 'bag', tmp_path / 'compare.pdf')
    assert list(tmp_path.iterdir()) == []
