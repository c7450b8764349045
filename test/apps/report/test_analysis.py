"""``lumpbeam analyze --report``: a bag stamped with a real clock, analysed and read back."""

from dataclasses import replace

import pytest
from figures import png_size

from lumpbeam_ros.apps.report.analysis import (
    CROSS_CHECKS,
    FIT_FACTS,
    fit_residual_figure,
    write_analysis_report,
)
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.ident.bag_analysis import CONTRACT_KEYS, analyze_bag, result_json
from lumpbeam_ros.core.ident.identification import Identification, Status
from lumpbeam_ros.core.ident.settings import IdentifierConfig
from lumpbeam_ros.core.model.parameters import load_beam_config

from .helpers import T0, parse_page, write_epoch_drop

#: The figures: the fit and residual, then plots/analysis.py's three (at 110 dpi).
SIZES = {
    'fit and residual': (990, 660),
    'trajectory': (990, 495),
    'spectrum': (770, 440),
    'estimates': (770, 440),
}


@pytest.fixture(scope='module')
def analysis(tmp_path_factory):
    bag = tmp_path_factory.mktemp('report') / 'drop'
    write_epoch_drop(bag)
    beam, _ = load_beam_config()
    return analyze_bag(bag, beam, IdentifierConfig(), show_progress=False)


@pytest.fixture(scope='module')
def page(analysis, tmp_path_factory):
    path = write_analysis_report(analysis, tmp_path_factory.mktemp('page') / 'analyze.html')
    return parse_page(path.read_text(encoding='utf-8'))


def test_the_page_names_the_bag_and_its_poses(analysis, page):
    assert analysis.result.ok
    assert page.title == 'lumpbeam analyze: drop'
    text, _ = page.paragraphs[0]
    assert text.startswith(f'{analysis.bag}: {len(analysis.window)} poses over ')
    assert 'status OK' in text
    assert page.h2 == ['Estimates (1 sigma)', 'The fit']


def test_the_estimates_table_lists_every_key_in_order(page):
    header, *rows = page.tables[0]
    assert header == ['estimate', 'value', 'std']
    assert [row[0] for row in rows] == list(CONTRACT_KEYS + CROSS_CHECKS)


def test_the_release_stamp_keeps_its_milliseconds(analysis, page):
    # The load leaves at 2 s after T0: an epoch stamp printed to 5 significant digits was
    # 1.7e+09; the table must show it to the millisecond.
    value, std = page.table_dict(0)['release_time_s']
    assert float(value) == pytest.approx(T0 + 2.0, abs=0.01)
    assert float(value) == pytest.approx(result_json(analysis.result)['release_time_s'], abs=1e-5)
    assert 0.0 < float(std) < 0.01


def test_the_estimates_match_the_result_to_five_digits(analysis, page):
    data = result_json(analysis.result)
    table = page.table_dict(0)
    for key in CONTRACT_KEYS:
        value, std = table[key]
        assert float(value) == pytest.approx(data[key], rel=1e-4), key
        assert float(std) == pytest.approx(data[f'{key}_std'], rel=1e-4), key
    # The configured beam's first mode, the synthetic bag's truth (doc/interfaces.md).
    assert float(table['natural_frequency_hz'][0]) == pytest.approx(3.06, rel=0.02)


def test_the_fit_table_shows_the_facts(analysis, page):
    header, *rows = page.tables[1]
    assert header == ['figure', 'value']
    assert [row[0] for row in rows] == list(FIT_FACTS)
    facts = page.table_dict(1)
    assert facts['status'] == ['OK']
    assert int(facts['n_samples'][0]) == result_json(analysis.result)['n_samples']


def test_every_figure_is_a_png_of_its_size(page):
    assert [alt for alt, _ in page.images] == list(SIZES)
    assert page.captions == list(SIZES)
    for alt, data in page.images:
        assert png_size(data) == SIZES[alt], alt


def test_the_fit_figure_alone(analysis):
    assert png_size(fit_residual_figure(analysis)) == SIZES['fit and residual']


def test_a_failed_identification_has_no_fit_figure(analysis, tmp_path):
    failed = replace(analysis, result=Identification(Status.ERROR, 'no release'), fit=None)
    assert fit_residual_figure(failed) is None
    page = parse_page(write_analysis_report(failed, tmp_path / 'r.html').read_text())
    assert 'status ERROR (no release)' in page.paragraphs[0][0]
    assert ('No decay was fitted, so there is no fit or residual to show.', 'note') in (
        page.paragraphs
    )
    assert [alt for alt, _ in page.images] == ['trajectory', 'spectrum', 'estimates']
    assert page.table_dict(0)['natural_frequency_hz'] == ['n/a', 'n/a']


def test_a_path_that_is_not_html_is_refused_before_any_file(analysis, tmp_path):
    with pytest.raises(LumpbeamError, match='the report is an HTML file'):
        write_analysis_report(analysis, tmp_path / 'analyze.png')
    assert list(tmp_path.iterdir()) == []
