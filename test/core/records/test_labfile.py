from pathlib import Path

import numpy as np
import pytest
from scipy.io import savemat

from lumpbeam_ros.base.errors import RecordError
from lumpbeam_ros.core.records.labfile import ChannelChoice, read_lab_file

REAL_LVM = Path(__file__).parents[2] / 'data' / 'records' / 'shaker_cantilever_test3_400hz.lvm'


def _lvm(
    rows: list[str],
    *,
    x_columns: str = 'One',
    decimal: str = '.',
    separator: str = 'Tab',
    names: str | None = 'X_Value\tacc\tComment',
    channels: int = 1,
    delta_x: str = '0.001',
) -> str:
    header = [
        'LabVIEW Measurement\t',
        'Writer_Version\t2',
        f'Separator\t{separator}',
        f'Decimal_Separator\t{decimal}',
        f'X_Columns\t{x_columns}',
        '***End_of_Header***\t',
        '\t',
        f'Channels\t{channels}\t',
        'Samples\t4\t',
        'X0\t0.0000000000000000E+0\t',
        f'Delta_X\t{delta_x}\t',
        '***End_of_Header***\t',
    ]
    return '\r\n'.join(header + ([names] if names is not None else []) + rows) + '\r\n'


def test_a_real_labview_file_is_read_by_its_x_values_not_its_stale_delta_x():
    record = read_lab_file(REAL_LVM, ChannelChoice(column='Acceleration'))
    assert record.name == 'Acceleration' and record.values.size == 1200
    # Its header's Delta_X is the 51.2 kHz original's; the X_Value column steps 2.5 ms.
    assert record.rate_hz == pytest.approx(400.0)
    assert record.t[0] == 0.0 and record.t[-1] == pytest.approx(2.9975)
    assert record.values[:2] == pytest.approx([0.024686, 0.005152])
    assert record.gaps == 0


def test_the_real_record_shows_the_shaker_lines():
    record = read_lab_file(REAL_LVM, ChannelChoice(column='acceleration'))
    v = record.values - record.values.mean()
    spectrum = np.abs(np.fft.rfft(v * np.hanning(v.size)))
    f = np.fft.rfftfreq(v.size, 1 / record.rate_hz)
    peaks = 1 + np.flatnonzero((spectrum[1:-1] > spectrum[:-2]) & (spectrum[1:-1] > spectrum[2:]))
    strongest = sorted(f[peaks[np.argsort(spectrum[peaks])[-3:]]])
    assert strongest == pytest.approx([100.0, 120.0, 150.0], abs=0.5)


def test_a_file_of_several_channels_asks_for_one_by_name():
    with pytest.raises(RecordError, match=r"3 channels \('Voltage', 'Force', 'Acceleration'\)"):
        read_lab_file(REAL_LVM)
    with pytest.raises(RecordError, match="no channel 'Torque'"):
        read_lab_file(REAL_LVM, ChannelChoice(column='Torque'))


@pytest.mark.parametrize(
    ('rows', 'options', 'values', 't'),
    [
        (['0.0\t1.5', '0.5\t2.5'], {}, [1.5, 2.5], [0.0, 0.5]),
        # A decimal comma, as a European LabVIEW writes it.
        (['0,0\t1,5', '0,5\t2,5'], {'decimal': ','}, [1.5, 2.5], [0.0, 0.5]),
        # No X column: time from X0 and Delta_X.
        (
            ['1.5', '2.5', '3.5'],
            {'x_columns': 'No', 'names': 'acc'},
            [1.5, 2.5, 3.5],
            [0, 1e-3, 2e-3],
        ),
        # One X column per channel.
        (
            ['0\t1\t0\t7', '2\t3\t2\t9'],
            {'x_columns': 'Multi', 'names': 'X_Value\tother\tX_Value\tacc', 'channels': 2},
            [7.0, 9.0],
            [0.0, 2.0],
        ),
        # A comma separator; an empty cell is a gap.
        (
            ['0,1', '1,', '2,3'],
            {'separator': 'Comma', 'names': 'X_Value,acc'},
            [1.0, np.nan, 3.0],
            [0, 1, 2],
        ),
    ],
)
def test_labview_layouts(tmp_path, rows, options, values, t):
    path = tmp_path / 'r.lvm'
    path.write_text(_lvm(rows, **options), encoding='utf-8')
    record = read_lab_file(path, ChannelChoice(column='acc'))
    np.testing.assert_allclose(record.values, values)
    np.testing.assert_allclose(record.t, t)


@pytest.mark.parametrize(
    ('text', 'suffix', 'options', 'values', 't'),
    [
        ('time,acc\n0,1\n0.1,2\n', '.csv', {'time_column': 'time'}, [1, 2], [0, 0.1]),
        ('t;acc\n0;1,5\n0,1;2,5\n', '.csv', {'time_column': 't'}, [1.5, 2.5], [0, 0.1]),
        (
            'acc\ttemp\n1\t20\n2\t21\n',
            '.tsv',
            {'column': 'acc', 'rate_hz': 10.0},
            [1, 2],
            [0, 0.1],
        ),
        # A byte-order mark, blank lines, quotes and a gap.
        (
            '\ufeff"time","acc"\n0,1\n\n1,\n2,3\n',
            '.csv',
            {'time_column': 'time'},
            [1, np.nan, 3],
            [0, 1, 2],
        ),
        # numpy.savetxt's layout: columns apart by spaces, the names after a '#'.
        (
            '# time(s), \t acc(g)\n0.0e+00 1.5e+00\n1.0e-01  2.5e+00\n',
            '.txt',
            {'time_column': 'time(s)', 'column': 'acc(g)'},
            [1.5, 2.5],
            [0, 0.1],
        ),
        ('# t acc\n0 1\n0.1 2\n', '.txt', {'time_column': 't'}, [1, 2], [0, 0.1]),
    ],
)
def test_csv_files(tmp_path, text, suffix, options, values, t):
    path = tmp_path / f'r{suffix}'
    path.write_text(text, encoding='utf-8')
    record = read_lab_file(path, ChannelChoice(**options))
    np.testing.assert_allclose(record.values, values)
    np.testing.assert_allclose(record.t, t)


def test_numpy_and_matlab_files(tmp_path):
    t, acc = np.arange(5) * 0.01, np.arange(5.0) ** 2
    np.save(tmp_path / 'one.npy', acc)
    np.save(tmp_path / 'two.npy', np.column_stack([t, acc]))
    np.savez(tmp_path / 'named.npz', time=t, acc=acc)
    savemat(tmp_path / 'named.mat', {'time': t, 'acc': acc[:, None]})
    cases = [
        ('one.npy', ChannelChoice(rate_hz=100.0)),
        ('two.npy', ChannelChoice(column='1', time_column='0')),
        ('named.npz', ChannelChoice(column='acc', time_column='time')),
        ('named.mat', ChannelChoice(column='acc', time_column='time')),
        ('named.mat', ChannelChoice(time_column='time')),  # the one variable left
    ]
    for name, choice in cases:
        record = read_lab_file(tmp_path / name, choice)
        np.testing.assert_allclose(record.values, acc, err_msg=name)
        np.testing.assert_allclose(record.t, t, err_msg=name)


@pytest.mark.parametrize(
    ('name', 'content', 'choice', 'message'),
    [
        ('r.xlsx', 'x', ChannelChoice(), "unknown kind of file '.xlsx'"),
        ('r.csv', None, ChannelChoice(), 'no such file'),
        ('r.csv', '', ChannelChoice(), 'empty file'),
        ('r.csv', 'acc\n1\n2\n', ChannelChoice(), 'no time for'),
        ('r.csv', 'acc\n1\n2\n', ChannelChoice(rate_hz=0.0), 'rate must be a positive'),
        ('r.csv', 'acc\n1\n2\n', ChannelChoice(rate_hz=float('nan')), 'rate must be a positive'),
        ('r.csv', '0,1\n1,2\n', ChannelChoice(rate_hz=1.0), 'the first row holds numbers'),
        (
            'r.csv',
            't,acc\n0,1\n1,2\n',
            ChannelChoice(time_column='t', column='accel'),
            "no column 'accel'",
        ),
        (
            'r.csv',
            't,acc\n0,1\n1,high\n',
            ChannelChoice(time_column='t'),
            "line 3, column 'acc': 'high' is not a number",
        ),
        (
            'r.csv',
            't,acc\n0,1\n0,2\n',
            ChannelChoice(time_column='t'),
            'time does not increase at sample 1',
        ),
        ('r.csv', 't,acc\n1,1\n0,2\n', ChannelChoice(time_column='t'), 'time does not increase'),
        (
            'r.csv',
            't,acc\n0,1\n,2\n',
            ChannelChoice(time_column='t'),
            'time is not a number at sample 1',
        ),
        ('r.csv', 't,acc\n0,1\n', ChannelChoice(time_column='t'), 'holds 1 sample'),
        ('r.csv', 't,acc\n0,\n1,\n', ChannelChoice(time_column='t'), 'holds no numeric value'),
        (
            'r.csv',
            't,a,b\n0,1,2\n1,2,3\n',
            ChannelChoice(time_column='t'),
            "2 columns \\('a', 'b'\\)",
        ),
        ('r.lvm', 'time,acc\n', ChannelChoice(), 'not a LabVIEW measurement file'),
        (
            'r.lvm',
            'LabVIEW Measurement\n***End_of_Header***\n',
            ChannelChoice(),
            'without its channel header',
        ),
        (
            'r.lvm',
            _lvm(['0\t1', '1\t2']),
            ChannelChoice(time_column='X_Value'),
            'gives its own time',
        ),
        ('r.lvm', _lvm(['0\t1', '1\tabc']), ChannelChoice(), "data row 2, channel 'acc': 'abc'"),
        ('r.lvm', _lvm(['0\t1']) + _lvm(['0\t1'])[1:], ChannelChoice(), 'segments'),
        ('r.lvm', _lvm(['0\t1'], separator='Semicolon'), ChannelChoice(), 'unknown separator'),
        ('r.npy', b'not numpy', ChannelChoice(rate_hz=1.0), 'not a NumPy file'),
        ('r.mat', b'not matlab', ChannelChoice(rate_hz=1.0), 'not a MATLAB file'),
    ],
)
def test_bad_files_are_one_line_naming_the_file(tmp_path, name, content, choice, message):
    path = tmp_path / name
    if isinstance(content, bytes):
        path.write_bytes(content)
    elif content is not None:
        path.write_text(content, encoding='utf-8')
    with pytest.raises(RecordError, match=message) as caught:
        read_lab_file(path, choice)
    assert str(path) in str(caught.value) and '\n' not in str(caught.value)


@pytest.mark.parametrize(
    ('array', 'choice', 'message'),
    [
        (np.zeros((3, 2)), ChannelChoice(rate_hz=1.0), 'choose its column with --column INDEX'),
        (np.zeros((3, 2)), ChannelChoice(column='2', rate_hz=1.0), 'outside 0..1'),
        (np.zeros((3, 2)), ChannelChoice(column='acc', rate_hz=1.0), 'not an index'),
        (np.zeros((2, 2, 2)), ChannelChoice(rate_hz=1.0), 'a 3-D array'),
        (np.array(['a', 'b']), ChannelChoice(rate_hz=1.0), 'not numbers'),
        (np.zeros(3, complex), ChannelChoice(rate_hz=1.0), 'complex'),
        (np.zeros(3), ChannelChoice(time_column='0'), 'no time column'),
    ],
)
def test_bad_numpy_arrays(tmp_path, array, choice, message):
    np.save(tmp_path / 'r.npy', array)
    with pytest.raises(RecordError, match=message):
        read_lab_file(tmp_path / 'r.npy', choice)


def test_a_pickled_numpy_file_is_refused_unread(tmp_path):
    np.save(tmp_path / 'r.npy', np.array([{'a': 1}], dtype=object), allow_pickle=True)
    with pytest.raises(RecordError, match='not a NumPy file NumPy can read safely'):
        read_lab_file(tmp_path / 'r.npy', ChannelChoice(rate_hz=1.0))


def test_a_matlab_matrix_is_not_a_vector(tmp_path):
    savemat(tmp_path / 'r.mat', {'acc': np.zeros((3, 3))})
    with pytest.raises(RecordError, match=r"'acc' has shape \(3, 3\), not a vector"):
        read_lab_file(tmp_path / 'r.mat', ChannelChoice(rate_hz=1.0))


def test_a_matlab_v73_file_says_how_to_save_it(tmp_path):
    # A v7.3 file is HDF5 behind MATLAB's 128-byte header, whose version field says 0x0200.
    header = b'MATLAB 7.3 MAT-file'.ljust(116, b' ') + bytes(8) + b'\x00\x02' + b'IM'
    (tmp_path / 'r.mat').write_bytes(header + b'\x89HDF\r\n\x1a\n' + bytes(64))
    with pytest.raises(RecordError, match=r'v7\.3 \(HDF5\) file; save it with -v7'):
        read_lab_file(tmp_path / 'r.mat', ChannelChoice(rate_hz=1.0))
