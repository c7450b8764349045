import pytest

from lumpbeam_ros.core.vision.sources import FootageError, FrameStamps


def test_fps_stamps_are_exact_nanoseconds():
    stamps = FrameStamps.from_fps(180.0, 1.95)
    assert stamps.count is None
    assert stamps.ns(0, 'v') == 1_950_000_000
    assert stamps.ns(1, 'v') == 1_955_555_556
    assert stamps.ns(180_000, 'v') == 1_950_000_000 + 1000 * 1_000_000_000


def test_timestamps_file_keeps_every_nanosecond(tmp_path):
    path = tmp_path / 't.txt'
    path.write_text('# camera clock\n1732000000.123456789\n\n1732000000.129012345\n')
    stamps = FrameStamps.from_file(path)
    assert stamps.listed_ns == (1_732_000_000_123_456_789, 1_732_000_000_129_012_345)
    stamps.check_covers(2, 'v')
    with pytest.raises(FootageError, match='t.txt has 2 stamps but clip.avi has 3 frames'):
        stamps.check_covers(3, 'clip.avi')
    with pytest.raises(FootageError, match='has 2 stamps but clip.avi has more frames'):
        stamps.ns(2, 'clip.avi')


@pytest.mark.parametrize(
    ('text', 'match'),
    [
        ('0.1\nabc\n', r't.txt:2: .abc. is not a time'),
        ('0.2\n0.1\n', 't.txt:2: stamp 0.1 does not increase'),
        ('-1\n', 'must be finite and >= 0'),
        ('nan\n', 'must be finite and >= 0'),
        ('# nothing\n', 'holds no stamp'),
    ],
)
def test_bad_timestamps_files_name_the_line(tmp_path, text, match):
    path = tmp_path / 't.txt'
    path.write_text(text)
    with pytest.raises(FootageError, match=match):
        FrameStamps.from_file(path)


@pytest.mark.parametrize(('fps', 'start'), [(0.0, 0.0), (-5.0, 0.0), (float('inf'), 0.0),
                                            (30.0, -1.0)])  # fmt: skip
def test_bad_rates_are_refused(fps, start):
    with pytest.raises(FootageError):
        FrameStamps.from_fps(fps, start)


def test_missing_timestamps_file(tmp_path):
    with pytest.raises(FootageError, match='nope.txt: cannot read'):
        FrameStamps.from_file(tmp_path / 'nope.txt')
