"""Campaigns on a real Dask LocalCluster (one worker process) and through the CLI."""

import contextlib
import io
import shutil
import socket

import pyarrow.parquet as pq
import pytest

from apps.campaign.conftest import LOADS, truncate_bag
from lumpbeam_ros.apps.campaign.engine import run_campaign, run_serial
from lumpbeam_ros.apps.campaign.store import ResultsStore
from lumpbeam_ros.apps.campaign.task import CampaignOptions
from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.core.ident.settings import load_identifier_config
from lumpbeam_ros.core.model.parameters import load_beam_config


@pytest.fixture(scope='module')
def settings():
    beam, _ = load_beam_config()
    return CampaignOptions(beam, load_identifier_config())


@pytest.fixture
def bags_with_a_cut_one(campaign_bags, tmp_path):
    cut = tmp_path / 'cut'
    shutil.copytree(campaign_bags[1], cut)
    truncate_bag(cut, 0.4)
    return [*campaign_bags, cut]


def test_campaign_rows_errors_and_resume(bags_with_a_cut_one, settings, tmp_path):
    store = ResultsStore(tmp_path / 'out')
    run = run_campaign(bags_with_a_cut_one, store, settings, workers=1)
    assert (run.submitted, run.skipped, run.failed, run.workers) == (4, 0, 1, 1)
    table = pq.read_table(tmp_path / 'out' / 'results.parquet').to_pylist()
    rows = {r['path']: r for r in table}
    cut = rows[str(bags_with_a_cut_one[-1])]
    # The reader keeps the 2 s before the cut (it warns on stderr), which end at the release:
    # no oscillation to identify, so the row is an error without an estimate.
    assert 'no estimate' in cut['error'] and cut['natural_frequency_hz'] is None
    good = [rows[str(b)] for b in bags_with_a_cut_one[:-1]]
    assert [r['error'] for r in good] == ['', '', '']
    assert [r['load_kg'] for r in good] == pytest.approx(LOADS)
    assert all(r['pose_count'] == 901 and r['duration_s'] > 4.9 for r in good)
    # The same rows as the plain loop: the worker runs the same code.
    (serial,) = run_serial(bags_with_a_cut_one[:1], settings)
    assert serial['natural_frequency_hz'] == good[0]['natural_frequency_hz']
    assert serial['key'] == good[0]['key']
    # A rerun skips what is done and retries only the failed bag.
    again = run_campaign(bags_with_a_cut_one, ResultsStore(tmp_path / 'out'), settings, workers=1)
    assert (again.submitted, again.skipped, again.failed) == (1, 3, 1)


def _run(argv):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


def _closed_port() -> int:
    with socket.socket() as sock:
        sock.bind(('127.0.0.1', 0))
        return sock.getsockname()[1]


def test_cli_scheduler_that_does_not_answer(campaign_bags, tmp_path):
    address = f'tcp://127.0.0.1:{_closed_port()}'
    argv = ['campaign', str(campaign_bags[0]), '--out', str(tmp_path / 'out')]
    code, _, err = _run([*argv, '--scheduler', address, '--connect-timeout', '1'])
    assert code == 2
    assert err.count('\n') == 1 and address in err and 'no Dask scheduler answered' in err


@pytest.mark.parametrize(
    ('argument', 'message'),
    [('{tmp}/none*', 'matches no file or folder'), ('{tmp}', 'not a rosbag2 bag')],
)
def test_cli_bags_that_are_not_bags(tmp_path, argument, message):
    code, out, err = _run(
        ['campaign', argument.format(tmp=tmp_path), '--out', str(tmp_path / 'r')]
    )
    assert code == 2 and message in err and err.count('\n') == 1 and not out
    assert not (tmp_path / 'r').exists()


def test_cli_results_from_another_version(campaign_bags, tmp_path):
    import pyarrow as pa

    out = tmp_path / 'out'
    out.mkdir()
    pq.write_table(pa.table({'path': ['x']}), out / 'results.parquet')
    code, _, err = _run(['campaign', str(campaign_bags[0]), '--out', str(out)])
    assert code == 2 and 'written by campaign table version none' in err
    assert pq.read_table(out / 'results.parquet').column_names == ['path']


def test_cli_campaign_writes_table_and_report(campaign_bags, tmp_path):
    code, out, _ = _run(
        ['campaign', *map(str, campaign_bags), '--out', str(tmp_path / 'out'), '--workers', '1']
    )
    assert code == 0
    assert '3 bags: 3 run on 1 workers' in out and 'beam fit over 3 bags' in out
    for name in ('results.parquet', 'results.csv', 'report.html'):
        assert (tmp_path / 'out' / name).is_file()
    html = (tmp_path / 'out' / 'report.html').read_text()
    assert 'data:image/png;base64,' in html and 'EI, N m^2' in html
    # A rerun has nothing new to run: no rate of nothing over no time.
    code, out, _ = _run(
        ['campaign', *map(str, campaign_bags), '--out', str(tmp_path / 'out'), '--workers', '1']
    )
    assert code == 0 and '3 already done' in out and 'nan' not in out


#: A process that starts a local cluster of one worker and is interrupted (one Ctrl-C to
#: itself) as soon as the worker's process has started, while the cluster waits for it; it
#: exits 130 when interrupted, as the lumpbeam command does.
_INTERRUPTED_START = """
import contextlib, os, signal, sys
import multiprocessing.process
from lumpbeam_ros.apps.campaign.engine import start_client

start = multiprocessing.process.BaseProcess.start


def start_then_interrupt(process):
    start(process)
    multiprocessing.process.BaseProcess.start = start  # one Ctrl-C
    os.kill(os.getpid(), signal.SIGINT)


multiprocessing.process.BaseProcess.start = start_then_interrupt
# As the lumpbeam command does (its handlers come first): a test runner's worker may hand
# its children SIGINT ignored.
signal.signal(signal.SIGINT, signal.default_int_handler)
try:
    with contextlib.ExitStack() as stack:
        start_client(None, 1, stack)
        print('started', flush=True)
except KeyboardInterrupt:
    sys.exit(130)
"""


def test_a_signal_while_the_cluster_starts_leaves_no_traceback():
    import subprocess
    import sys

    # Rarely (a loaded machine) the start still ends before the interrupt is taken: again.
    for _ in range(3):
        child = subprocess.run(
            [sys.executable, '-c', _INTERRUPTED_START], capture_output=True, text=True, timeout=120
        )
        if 'started' not in child.stdout:
            break
    assert 'started' not in child.stdout, 'the signal came after the start every time: no test'
    assert child.returncode == 130 and 'Traceback' not in child.stderr, child.stderr
