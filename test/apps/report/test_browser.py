"""The HTML reports in a real headless browser: Debian's Chromium driven by Selenium.

The page must load from disk with the network off, every figure must decode
(``naturalWidth > 0``) and the browser console must stay free of errors. Skipped only when
Chromium is not installed outside CI; in CI (``CI=true``) a missing browser fails.
"""

import os
from pathlib import Path

import pytest

from lumpbeam_ros.apps.cli.main import main

CHROMIUM = Path('/usr/bin/chromium')
DRIVER = Path('/usr/bin/chromedriver')


@pytest.fixture(scope='module')
def browser(tmp_path_factory):
    if not (CHROMIUM.exists() and DRIVER.exists()):
        message = f'{CHROMIUM} or {DRIVER} missing (apt-get install chromium chromium-driver)'
        if os.environ.get('CI') == 'true':
            pytest.fail(message)
        pytest.skip(message)
    webdriver = pytest.importorskip('selenium.webdriver')
    options = webdriver.ChromeOptions()
    options.binary_location = str(CHROMIUM)
    for flag in (
        '--headless',
        '--no-sandbox',
        '--disable-gpu',
        '--disable-background-networking',
        '--disable-component-update',
        '--disable-sync',
        '--no-first-run',
        f'--user-data-dir={tmp_path_factory.mktemp("chromium")}',
    ):
        options.add_argument(flag)
    options.set_capability('goog:loggingPrefs', {'browser': 'ALL'})
    service = webdriver.ChromeService(executable_path=str(DRIVER))
    driver = webdriver.Chrome(options=options, service=service)
    yield driver
    driver.quit()


def _check_page(driver, page: Path) -> int:
    driver.get(page.as_uri())
    assert driver.execute_script('return document.readyState') == 'complete'
    widths = driver.execute_script(
        'return Array.from(document.images).map(i => i.complete ? i.naturalWidth : 0)'
    )
    assert widths and all(w > 0 for w in widths), widths
    errors = [e for e in driver.get_log('browser') if e['level'] == 'SEVERE']
    assert not errors, errors
    # Nothing is fetched: every resource is inline.
    assert 'http' not in driver.execute_script(
        'return Array.from(document.querySelectorAll("[src],[href]"))'
        '.map(e => e.getAttribute("src") || e.getAttribute("href")).join(" ")'
    )
    return len(widths)


def test_analyze_report_renders(browser, minimal_bag, tmp_path):
    analyze_page = tmp_path / 'analyze.html'
    assert main(['analyze', str(minimal_bag), '--report', str(analyze_page)]) == 0
    assert _check_page(browser, analyze_page) == 4  # fit and residual + the three figures


def test_diagnose_report_renders(browser, tmp_path):
    bag = tmp_path / 'late'
    assert main(['synth', str(bag), '--duration', '6', '--effect', 'sensor_latency=0.015']) == 0
    page = tmp_path / 'diagnose.html'
    assert main(['diagnose', str(bag), '--report', str(page)]) == 0
    assert _check_page(browser, page) >= 2
    text = page.read_text()
    assert 'sensor_latency' in text and 'gap' in text


def test_compare_report_renders(browser, tmp_path):
    bag = tmp_path / 'tracked'
    assert main(['synth', str(bag), '--duration', '5', '--tracker']) == 0
    page = tmp_path / 'compare.html'
    assert main(['compare', str(bag), '--report', str(page)]) == 0
    assert _check_page(browser, page) >= 1


def test_a_broken_figure_is_caught(browser, tmp_path):
    page = tmp_path / 'broken.html'
    page.write_text(
        '<!DOCTYPE html><html><body><img src="data:image/png;base64,AAAA"></body></html>'
    )
    with pytest.raises(AssertionError):
        _check_page(browser, page)


@pytest.fixture(scope='module')
def minimal_bag(tmp_path_factory):
    from lumpbeam_ros.core.model.parameters import DropTestConfig, load_beam_config
    from lumpbeam_ros.core.synthetic.drop_test import SynthOptions, write_drop_test_bag

    beam, _ = load_beam_config()
    bag = tmp_path_factory.mktemp('report') / 'drop'
    write_drop_test_bag(bag, beam, DropTestConfig(duration_s=5.0), SynthOptions(duration_s=5.0))
    return bag


def test_campaign_report_renders(browser, tmp_path):
    from lumpbeam_ros.apps.campaign.summary import summarize, write_campaign_report
    from lumpbeam_ros.core.model.parameters import load_beam_config

    beam, _ = load_beam_config()
    rows = [
        {
            'path': f'/b{i}',
            'error': '',
            'load_kg': m,
            'natural_frequency_hz': 3.06,
            'natural_frequency_hz_std': 1e-3,
            'damping_ratio': 2.4e-3,
            'damping_ratio_std': 1e-5,
            'stiffness_total_nm_per_rad': 3899.0,
            'stiffness_total_nm_per_rad_std': 2.0,
            'static_deflection_m': m * 9.81 * beam.length_m**3 / (3 * 4504.8),
            'static_deflection_m_std': 1e-5,
            'level_after_m': -0.0289,
            'level_after_m_std': 1e-5,
        }
        for i, m in enumerate((1.0, 2.0, 5.0))
    ] + [{'path': '/cut', 'error': 'cut short'}]
    page = write_campaign_report(summarize(rows, beam), tmp_path / 'report.html')
    assert _check_page(browser, page) == 1
    assert 'cut short' in page.read_text()
