"""``lumpbeam diagnose --report``: a late camera diagnosed, the page read back."""

import re
from dataclasses import replace

import pytest
from figures import png_size

from lumpbeam_ros.apps.report.diagnosis import GAP_COLUMNS, add_diagnosis, write_diagnosis_report
from lumpbeam_ros.apps.report.html import HtmlReport
from lumpbeam_ros.base.errors import LumpbeamError

from .helpers import late_diagnosis, parse_page

#: plots/diagnosis.py's figures at 120 dpi, by caption.
SIZES = {
    'diagnosis fit': (1200, 720),
    'diagnosis residuals': (1200, 480),
    'diagnosis signatures': (1800, 540),
    'diagnosis candidates': (1320, 480),
}


@pytest.fixture(scope='module')
def late():
    return late_diagnosis()


@pytest.fixture(scope='module')
def page(late, tmp_path_factory):
    path = tmp_path_factory.mktemp('page') / 'diagnose.html'
    assert write_diagnosis_report(late, '/bags/late', path) == path
    return parse_page(path.read_text(encoding='utf-8'))


def test_the_page_names_the_bag_the_effect_and_its_reason(late, page):
    assert late.missing_effect == 'sensor_latency'
    assert page.title == 'lumpbeam diagnose: late'
    assert page.paragraphs[0] == (f'/bags/late: {len(late.record)} poses', None)
    assert page.h2 == [
        'Missing effect: sensor_latency',
        'The gap between model and measurement',
        'Candidates (BIC on the fitted part, lower is better)',
    ]
    assert page.paragraphs[1] == (late.decision.reason, None)
    note, css = page.paragraphs[2]
    assert css == 'note' and f'{late.simulations} simulations' in note


def test_the_effect_parameter_is_the_hidden_latency(page):
    header, *rows = page.tables[0]
    assert header == ['effect parameter', 'value']
    ((name, value),) = rows
    assert name == 'latency_s'
    assert float(value) == pytest.approx(0.015, rel=0.2)  # hidden 15 ms, 20 um noise


def test_the_gap_table_closes_the_gap(late, page):
    header, *rows = page.tables[1]
    assert header == ['model', *GAP_COLUMNS]
    assert [row[0] for row in rows] == [
        'configured beam (as given)',
        'before: nominal, refit',
        'after: with sensor_latency',
    ]
    gaps = [late.gap_configured, late.gap_before, late.gap_after]
    for row, gap in zip(rows, gaps, strict=True):
        expected = gap.as_dict()
        for cell, column in zip(row[1:], GAP_COLUMNS, strict=True):
            assert float(cell) == pytest.approx(expected[column], rel=1e-4), column
    before, after = float(rows[1][1]), float(rows[2][1])
    assert after < 0.5 * before  # naming the latency explains most of the misfit


def test_the_candidates_table_has_the_nominal_model_then_each_effect(late, page):
    header, *rows = page.tables[2]
    assert header[:2] == ['candidate', 'BIC'] and header[-1] == 'parameters'
    scores = [late.nominal, *late.candidates]
    assert [row[0] for row in rows] == [s.name for s in scores]
    for row, score in zip(rows, scores, strict=True):
        assert float(row[1]) == pytest.approx(score.bic, rel=1e-4)
        assert row[4] in ('True', 'False')
    latency = next(row for row in rows if row[0] == 'sensor_latency')
    fitted = re.fullmatch(r'k_total_nm_per_rad = \S+, beta_identified = \S+, latency_s = (\S+)',
                          latency[5])  # fmt: skip
    assert fitted and float(fitted[1]) == pytest.approx(0.015, rel=0.2)


def test_every_figure_is_a_png_of_its_size(page):
    assert [alt for alt, _ in page.images] == list(SIZES)
    for alt, data in page.images:
        assert png_size(data) == SIZES[alt], alt


def test_no_effect_parameter_leaves_out_its_table(late, tmp_path):
    page = HtmlReport('none')
    add_diagnosis(page, replace(late, effect_parameters={}))
    parsed = parse_page(page.render())
    assert [table[0][0] for table in parsed.tables] == ['model', 'candidate']


def test_a_path_that_is_not_html_is_refused(late, tmp_path):
    with pytest.raises(LumpbeamError, match='the report is an HTML file'):
        write_diagnosis_report(late, 'bag', tmp_path / 'diagnose.json')
    assert list(tmp_path.iterdir()) == []
