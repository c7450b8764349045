import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from lumpbeam_ros.apps.campaign.store import VERSION_KEY, ResultsStore
from lumpbeam_ros.apps.campaign.task import SCHEMA_VERSION
from lumpbeam_ros.base.errors import LumpbeamError


def _row(path, key='k', error='', f=3.0):
    return {'path': path, 'key': key, 'error': error, 'natural_frequency_hz': f}


def test_rows_survive_a_new_store_and_resume_by_key(tmp_path):
    store = ResultsStore(tmp_path, flush_interval_s=0.0)
    store.add(_row('/a', 'ka'))
    store.add(_row('/b', 'kb', error='broken'))
    # A crash here: the files on disk already hold both rows.
    again = ResultsStore(tmp_path)
    assert [r['path'] for r in again.completed()] == ['/a', '/b']
    assert again.is_done('/a', 'ka')
    assert not again.is_done('/a', 'other')  # the bag changed
    assert not again.is_done('/b', 'kb')  # errors are retried
    csv = (tmp_path / 'results.csv').read_text().splitlines()
    assert csv[0].startswith('"path","key"') and len(csv) == 3
    assert not list(tmp_path.glob('.*tmp'))


def test_a_results_file_of_another_version_is_refused_and_kept(tmp_path):
    table = pa.table({'path': ['/a']}).replace_schema_metadata({VERSION_KEY: b'0'})
    pq.write_table(table, tmp_path / 'results.parquet')
    before = (tmp_path / 'results.parquet').read_bytes()
    with pytest.raises(LumpbeamError, match=f'version 0, this is version {SCHEMA_VERSION}'):
        ResultsStore(tmp_path)
    assert (tmp_path / 'results.parquet').read_bytes() == before


def test_an_unreadable_results_file_is_one_line(tmp_path):
    (tmp_path / 'results.parquet').write_bytes(b'not parquet')
    with pytest.raises(LumpbeamError, match='unreadable results file') as info:
        ResultsStore(tmp_path)
    assert '\n' not in str(info.value)


def test_a_failed_write_leaves_the_last_good_file(tmp_path, monkeypatch):
    store = ResultsStore(tmp_path, flush_interval_s=0.0)
    store.add(_row('/a'))
    good = (tmp_path / 'results.parquet').read_bytes()

    def half_written(table, where):
        with open(where, 'wb') as stream:
            stream.write(b'PAR1 half')
        raise OSError(28, 'No space left on device')

    monkeypatch.setattr(pq, 'write_table', half_written)
    with pytest.raises(LumpbeamError, match='No space left'):
        store.add(_row('/b'))
    assert (tmp_path / 'results.parquet').read_bytes() == good
    assert not list(tmp_path.glob('.*tmp'))


def test_out_must_be_a_folder(tmp_path):
    (tmp_path / 'file').write_text('x')
    with pytest.raises(LumpbeamError, match='not a folder'):
        ResultsStore(tmp_path / 'file')
