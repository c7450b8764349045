import html
import math

import numpy as np
import pytest

from lumpbeam_ros.apps.campaign.summary import (
    LOAD_RESOLUTION_KG,
    QUANTITIES,
    fit_dict,
    summarize,
    summary_figure,
    write_campaign_report,
)
from lumpbeam_ros.base.errors import LumpbeamError
from lumpbeam_ros.core.model.parameters import BeamParameters

BEAM = BeamParameters()
EI = BEAM.k_total_nm_per_rad * BEAM.length_m / 2.0  # B.6
LOADS = [1.0, 1.0, 1.0, 4.0, 4.0, 9.0]


def _row(load, k, noise=0.0):
    """One bag's row, its levels from the analytic cantilever (B.1, B.3, B.5)."""
    beam, length3, g = BEAM, BEAM.length_m**3, BEAM.gravity_mps2
    sag = beam.mass_kg * g * length3 / (8 * EI) + beam.tip_mass_kg * g * length3 / (3 * EI)
    return {
        'path': f'/bags/{load:g}kg_{k}',
        'error': '',
        'load_kg': load,
        'static_deflection_m': load * g * length3 / (3 * EI) + noise,
        'static_deflection_m_std': 1e-6,
        'level_after_m': -sag - noise,
        'level_after_m_std': 1e-6,
        'natural_frequency_hz': 3.05 + 0.01 * k,
        'natural_frequency_hz_std': 1e-3,
        'damping_ratio': 0.002 * (1 + k),
        'damping_ratio_std': 1e-5,
        'stiffness_total_nm_per_rad': BEAM.k_total_nm_per_rad + 10.0 * k,
        'stiffness_total_nm_per_rad_std': 5.0,
    }


def _rows():
    rows = [_row(load, k) for k, load in enumerate(LOADS)]
    rows.append({'path': '/bags/cut', 'error': '/bags/cut: the recording was cut'})
    rows.append({'path': '/bags/quiet', 'error': 'analyze: no estimate (no release)'})
    return rows


def test_rows_are_grouped_by_load_with_mean_and_spread():
    summary = summarize(_rows(), BEAM)
    assert (len(summary.rows), len(summary.ok)) == (8, 6)
    assert [g.load_kg for g in summary.groups] == [1.0, 4.0, 9.0]
    assert [g.n for g in summary.groups] == [3, 2, 1]
    for group in summary.groups:
        members = [_row(x, k) for k, x in enumerate(LOADS) if x == group.load_kg]
        for key, *_ in QUANTITIES:
            values = [m[key] for m in members]
            assert group.means[key] == pytest.approx(np.mean(values), rel=1e-12)
            if len(values) > 1:
                assert group.stds[key] == pytest.approx(np.std(values, ddof=1), rel=1e-12)
            else:
                assert math.isnan(group.stds[key])  # one bag has no spread


def test_the_beam_fit_gives_back_the_configured_beam():
    summary = summarize(_rows(), BEAM)
    fit = summary.beam_fit
    assert fit is not None and fit.n_bags == 6 and summary.beam_fit_error == ''
    configured = summary.configured
    assert configured['bending_stiffness_nm2'] == pytest.approx(EI)
    assert fit.bending_stiffness_nm2 == pytest.approx(EI, rel=1e-9)
    assert fit.k_total_nm_per_rad == pytest.approx(configured['k_total_nm_per_rad'], rel=1e-9)
    assert fit.beam_mass_kg == pytest.approx(configured['beam_mass_kg'], rel=1e-9)
    assert fit_dict(summary)['bending_stiffness_nm2'] == fit.bending_stiffness_nm2


def test_loads_within_the_resolution_are_one_group():
    rows = [_row(2.0, 0), _row(2.0 + 0.3 * LOAD_RESOLUTION_KG, 1), _row(2.0 + 1e-3, 2)]
    assert [g.n for g in summarize(rows, BEAM).groups] == [2, 1]


def test_missing_values_are_left_out_of_the_means_and_the_fit():
    rows = [_row(x, k) for k, x in enumerate(LOADS)]
    rows[1]['natural_frequency_hz'] = None  # a row of a results file, JSON null
    rows[2]['load_kg'] = None  # no /tip_load: in no group
    rows[3]['static_deflection_m_std'] = 0.0  # not a usable weight
    summary = summarize(rows, BEAM)
    assert [g.n for g in summary.groups] == [2, 2, 1]
    assert summary.groups[0].means['natural_frequency_hz'] == pytest.approx(3.05)
    assert summary.beam_fit is not None and summary.beam_fit.n_bags == 3


@pytest.mark.parametrize(
    'rows',
    [
        [],
        [_row(4.0, 0)],
        [{'path': '/b', 'error': 'cut'}],
        [_row(0.0, 0), _row(0.0, 1)],  # nothing released
    ],
    ids=['none', 'one bag', 'only failures', 'no load'],
)
def test_too_little_data_gives_no_fit_and_says_why(rows):
    summary = summarize(rows, BEAM)
    assert summary.beam_fit is None and fit_dict(summary) == {}
    assert 'at least two bags with a released load' in summary.beam_fit_error
    assert f'beam fit: none ({summary.beam_fit_error})' in summary.text()


def test_the_text_has_counts_table_fit_and_failures():
    text = summarize(_rows(), BEAM).text().splitlines()
    assert text[0] == '8 rows: 6 with results, 2 failed'
    assert 'natural frequency [Hz]' in text[1] and 'k_tE (B.12) [N m/rad]' in text[1]
    assert text[2].split()[:2] == ['1', '3'] and '3.06 +- 0.01' in text[2]
    assert text[4].split()[:2] == ['9', '1'] and '+-' not in text[4]  # one bag: no spread
    assert any(line.startswith('beam fit over 6 bags') for line in text)
    assert any(f'EI  = {EI:.6g} +- ' in line for line in text)
    # A message that names its bag is not prefixed with it again.
    assert text[-2:] == [
        'failed: /bags/cut: the recording was cut',
        'failed: /bags/quiet: analyze: no estimate (no release)',
    ]


def test_a_group_without_a_value_prints_n_a():
    row = _row(1.0, 0)
    row['damping_ratio'] = None
    assert 'n/a' in summarize([row], BEAM).text().splitlines()[2]


def test_the_figure_is_a_png(tmp_path):
    png = summary_figure(summarize(_rows(), BEAM))
    assert png[:8] == b'\x89PNG\r\n\x1a\n'
    from matplotlib.image import imread

    (tmp_path / 'f.png').write_bytes(png)
    height, width = imread(tmp_path / 'f.png').shape[:2]
    assert (width, height) == (11 * 110, 8 * 110)
    assert summary_figure(summarize([], BEAM))[:8] == b'\x89PNG\r\n\x1a\n'


def test_the_report_has_the_table_the_fit_and_the_failures(tmp_path):
    out = write_campaign_report(summarize(_rows(), BEAM), tmp_path / 'new' / 'report.html')
    page = html.unescape(out.read_text())
    assert '8 bags: 6 with results, 2 failed.' in page
    assert 'k_tE = 2 EI / L, N m/rad' in page and 'Bags without results' in page
    assert '/bags/cut: the recording was cut' in page and '<img' in page


def test_a_report_without_a_fit_says_why(tmp_path):
    out = write_campaign_report(summarize([_row(4.0, 0)], BEAM), tmp_path / 'r.html')
    page = out.read_text()
    assert 'No fit: the beam fit needs at least two bags' in page
    assert 'Bags without results' not in page


@pytest.mark.parametrize(
    ('name', 'match'),
    [('report.txt', 'the report is an HTML file'), ('a_file/report.html', 'cannot write')],
)
def test_a_report_that_cannot_be_written_is_a_clear_error(tmp_path, name, match):
    (tmp_path / 'a_file').write_text('x')
    with pytest.raises(LumpbeamError, match=match):
        write_campaign_report(summarize([], BEAM), tmp_path / name)


def test_the_diagnosed_effects_are_in_the_text_and_the_report(tmp_path):
    rows = [_row(load, k) for k, load in enumerate(LOADS)]
    rows[0].update(
        {'diagnosed': True, 'missing_effect': 'coulomb_friction',
         'effect_parameters.torque_nm': 1.003}
    )  # fmt: skip
    rows[1].update({'diagnosed': True, 'missing_effect': 'none'})
    summary = summarize(rows, BEAM)
    assert summary.diagnoses == [
        ('/bags/1kg_0', 'coulomb_friction', 'torque_nm = 1.003'),
        ('/bags/1kg_1', 'none', ''),
    ]
    text = summary.text().splitlines()
    assert 'diagnosis: /bags/1kg_0: coulomb_friction (torque_nm = 1.003)' in text
    page = html.unescape(write_campaign_report(summary, tmp_path / 'r.html').read_text())
    assert 'The diagnosis of each bag' in page and 'torque_nm = 1.003' in page
    # The method is in words, not the module's reStructuredText.
    assert '``' not in page and 'L^3 / (3 EI)' in page
