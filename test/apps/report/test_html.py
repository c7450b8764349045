"""The report page: cells, blocks, figures and the file, read back with an HTML parser."""

import math

import matplotlib.pyplot as plt
import pytest
from figures import png_size

from lumpbeam_ros.apps.report.html import (
    HtmlReport,
    as_cell,
    estimate_rows,
    figure_png,
    format_value,
)
from lumpbeam_ros.base.errors import LumpbeamError

from .helpers import parse_page, tiny_png

STAMP = 1_700_000_123.456789  # an epoch stamp, s, as a real bag's header carries


@pytest.mark.parametrize(
    ('value', 'text'),
    [
        (None, 'n/a'),
        (math.nan, 'n/a'),
        (math.inf, 'n/a'),
        (-math.inf, 'n/a'),
        (True, 'True'),
        (False, 'False'),
        (0, '0'),
        (-42, '-42'),
        (12345678901, '12345678901'),
        (0.0, '0'),
        (3.0612345, '3.0612'),
        (-0.00123456789, '-0.0012346'),
        (2.4e-7, '2.4e-07'),
        (99999.4, '99999'),
        (STAMP, '1700000123.45679'),
        (-STAMP, '-1700000123.45679'),
        (1_700_000_000.5, '1700000000.5'),
        (123456.0, '123456'),
        (1e20, '1e+20'),
        ('beam_base', 'beam_base'),
        ('', ''),
    ],
    ids=lambda v: repr(v),
)
def test_format_value(value, text):
    assert format_value(value) == text


@pytest.mark.parametrize('value', [STAMP, 1_699_999_999.000_01, 3.14159e5, 186_400.25])
def test_a_large_value_keeps_its_fraction(value):
    # The bug: '%.5g' printed an epoch stamp as 1.7e+09, rounding away years.
    assert float(format_value(value)) == pytest.approx(value, abs=1e-5)


def test_fewer_digits_on_request():
    assert format_value(math.pi, digits=3) == '3.14'
    assert format_value(1234.5678, digits=3) == '1234.568'


def test_as_cell_keeps_numbers_and_text_and_stringifies_the_rest():
    assert (
        as_cell(1.5) == 1.5 and as_cell(3) == 3 and as_cell('x') == 'x' and as_cell(None) is None
    )
    assert as_cell([1, 2]) == '[1, 2]'
    assert as_cell({'a': 1}) == "{'a': 1}"


def test_estimate_rows_pair_each_key_with_its_std():
    data = {'f_hz': 3.06, 'f_hz_std': 0.001, 'status': 'ok', 'list': [1]}
    rows = estimate_rows(data, ['f_hz', 'status', 'missing', 'list'])
    assert rows == [
        ['f_hz', 3.06, 0.001],
        ['status', 'ok', None],
        ['missing', None, None],
        ['list', '[1]', None],
    ]


def test_a_page_parses_with_its_blocks_in_order():
    page = HtmlReport('Drop <1> & "2"')
    page.heading('Estimates & <std>')
    page.paragraph('a < b', note=True)
    page.paragraph('plain')
    page.table(['name', 'value', 'std'], [['f', 3.0612345, None], ['stamp', STAMP, math.nan]])
    page.png(tiny_png(), 'the <fit>')
    parsed = parse_page(page.render())
    assert parsed.title == 'Drop <1> & "2"' and parsed.h1 == ['Drop <1> & "2"']
    assert parsed.h2 == ['Estimates & <std>']
    assert parsed.paragraphs == [('a < b', 'note'), ('plain', None)]
    assert parsed.tables == [
        [['name', 'value', 'std'], ['f', '3.0612', 'n/a'], ['stamp', '1700000123.45679', 'n/a']]
    ]
    assert parsed.order == ['h1', 'h2', 'p', 'p', 'table', 'figure']
    ((alt, png),) = parsed.images
    assert alt == 'the <fit>' and png == tiny_png()
    assert parsed.captions == ['the <fit>']
    # Self-contained: the only links are data URIs.
    assert parsed.links and all(link.startswith('data:') for link in parsed.links)


def test_the_first_column_is_the_name_column():
    page = HtmlReport('t')
    page.table(['a', 'b'], [['x', 1.0]])
    html = page.render()
    assert '<th class=name>a</th><th>b</th>' in html
    assert '<td class=name>x</td><td>1</td>' in html


@pytest.mark.parametrize(
    'data',
    [b'', b'GIF89a', b'\x89PNG\r\n', b'<svg/>', b'\x89PNG\r\n\x1b\n rest'],
    ids=['empty', 'gif', 'short-signature', 'svg', 'wrong-byte'],
)
def test_not_a_png_is_refused(data):
    page = HtmlReport('t')
    with pytest.raises(LumpbeamError, match="figure 'fit' is not a PNG image"):
        page.png(data, 'fit')
    assert page.blocks == []


def test_png_files_are_embedded_with_their_names_as_captions(tmp_path):
    files = [tmp_path / 'fit_and_residual.png', tmp_path / 'envelope.png']
    for path in files:
        path.write_bytes(tiny_png())
    page = HtmlReport('t')
    page.png_files(files)
    parsed = parse_page(page.render())
    assert [alt for alt, _ in parsed.images] == ['fit and residual', 'envelope']
    assert all(data == tiny_png() for _, data in parsed.images)


def test_figure_png_is_the_figure_at_its_size_and_closes_it():
    fig = plt.figure(figsize=(4, 3))
    fig.add_subplot().plot([0, 1], [1, 0])
    data = figure_png(fig, dpi=50)
    assert png_size(data) == (200, 150)
    assert not plt.fignum_exists(fig.number)


@pytest.mark.parametrize('name', ['report.html', 'REPORT.HTM', 'deep/er/page.html'])
def test_write_creates_the_folder_and_leaves_no_temporary(tmp_path, name):
    page = HtmlReport('written')
    page.paragraph('x')
    path = page.write(tmp_path / name)
    assert path == tmp_path / name
    assert parse_page(path.read_text(encoding='utf-8')).title == 'written'
    assert [p.name for p in path.parent.iterdir()] == [path.name]


def test_write_replaces_an_older_page(tmp_path):
    HtmlReport('old').write(tmp_path / 'r.html')
    HtmlReport('new').write(tmp_path / 'r.html')
    assert parse_page((tmp_path / 'r.html').read_text()).title == 'new'


@pytest.mark.parametrize('name', ['report.png', 'report', 'report.html.txt'])
def test_write_refuses_a_path_that_is_not_html(tmp_path, name):
    with pytest.raises(LumpbeamError, match='the report is an HTML file'):
        HtmlReport('t').write(tmp_path / name)
    assert list(tmp_path.iterdir()) == []


def test_an_unwritable_place_is_one_clear_line(tmp_path):
    blocker = tmp_path / 'file'
    blocker.write_text('x')
    with pytest.raises(LumpbeamError, match='cannot write the report') as info:
        HtmlReport('t').write(blocker / 'r.html')
    assert '\n' not in str(info.value) and str(blocker / 'r.html') in str(info.value)
