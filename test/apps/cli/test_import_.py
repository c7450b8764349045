from pathlib import Path

import pytest

from lumpbeam_ros.apps.cli.main import main
from lumpbeam_ros.core.bagio import read_accelerations, read_tip_poses

REAL_LVM = Path(__file__).parents[2] / 'data' / 'records' / 'shaker_cantilever_test3_400hz.lvm'


def test_a_real_labview_record_becomes_a_tip_imu_bag(tmp_path, capsys, mcap_doctor):
    out = tmp_path / 'shaker'
    args = [str(REAL_LVM), str(out), '--quantity', 'acceleration', '--unit', 'g']
    assert main(['import', *args, '--column', 'Acceleration']) == 0
    printed = capsys.readouterr().out
    assert f"wrote {out}: 1200 messages on /tip_imu from 'Acceleration'" in printed
    assert '2.9975 s at 400 Hz from 2000-01-01T00:00:00+00:00' in printed
    assert len(read_accelerations(out).t) == 1200
    assert mcap_doctor(out) == ''


def test_a_csv_with_a_gap_warns_and_keeps_the_rest(tmp_path, capsys):
    src = tmp_path / 'tip.csv'
    src.write_text('time;z\n0;1,5\n0,01;\n0,02;2,5\n', encoding='utf-8')
    out = tmp_path / 'b'
    args = ['import', str(src), str(out), '--quantity', 'displacement', '--unit', 'mm']
    assert main([*args, '--time-column', 'time']) == 0
    captured = capsys.readouterr()
    assert "1 sample(s) of 'z' without a value left out" in captured.err
    assert list(read_tip_poses(out).z) == pytest.approx([1.5e-3, 2.5e-3])


def _exit_code(argv: list[str]) -> int:
    """The exit code of a run, argparse's refusals (SystemExit) included."""
    try:
        return main(argv)
    except SystemExit as exc:
        return int(exc.code)


@pytest.mark.parametrize(
    ('extra', 'message'),
    [
        (['--quantity', 'acceleration', '--unit', 'mm'], "unit 'mm' is not one of a acceleration"),
        (['--quantity', 'displacement'], 'no time for'),
        (['--quantity', 'displacement', '--rate', '-5'], 'must be a positive number'),
        (['--quantity', 'displacement', '--rate', '5', '--time-column', 't'], 'not allowed with'),
        (['--quantity', 'displacement', '--rate', '5', '--start', 'noon'], 'not an ISO 8601 time'),
        (['--quantity', 'force', '--rate', '5'], "invalid choice: 'force'"),
    ],
)
def test_bad_options_are_one_line_and_exit_2(tmp_path, capsys, extra, message):
    src = tmp_path / 'tip.csv'
    src.write_text('z\n1\n2\n', encoding='utf-8')
    assert _exit_code(['import', str(src), str(tmp_path / 'b'), *extra]) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / 'b').exists()


def test_an_existing_bag_is_not_overwritten(tmp_path, capsys):
    src = tmp_path / 'tip.csv'
    src.write_text('z\n1\n2\n', encoding='utf-8')
    (tmp_path / 'b').mkdir()
    assert (
        main(
            ['import', str(src), str(tmp_path / 'b'), '--quantity', 'displacement', '--rate', '5']
        )
        == 2
    )
    assert 'exists already' in capsys.readouterr().err
