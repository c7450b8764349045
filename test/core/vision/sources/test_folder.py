import cv2
import numpy as np
import pytest

from lumpbeam_ros.core.vision.sources import FolderSource, FootageError, FrameStamps, open_footage


def test_images_are_read_in_name_order_and_a_bad_file_is_a_lost_frame(tmp_path):
    for i in (2, 0, 1):
        cv2.imwrite(str(tmp_path / f'{i:04d}.png'), np.full((8, 10), 10 * i, np.uint8))
    (tmp_path / '0003.jpg').write_bytes(b'not a jpeg')
    (tmp_path / 'notes.txt').write_text('ignored')
    frames = list(FolderSource(tmp_path, FrameStamps.from_fps(10.0)))
    assert [f.label.rsplit('/', 1)[1] for f in frames] == ['0000.png', '0001.png', '0002.png',
                                                            '0003.jpg']  # fmt: skip
    assert [int(f.pixels[0, 0]) for f in frames[:3]] == [0, 10, 20]
    assert frames[3].pixels is None and frames[3].problem == 'cannot decode'
    assert frames[2].stamp_ns == 200_000_000


@pytest.mark.parametrize('case', ['empty', 'no stamps', 'too few stamps', 'missing'])
def test_bad_folders_are_one_line(tmp_path, case):
    folder = tmp_path / 'frames'
    folder.mkdir()
    stamps = FrameStamps.from_fps(10.0)
    if case != 'empty':
        for i in range(3):
            cv2.imwrite(str(folder / f'{i}.png'), np.zeros((8, 8), np.uint8))
    if case == 'no stamps':
        stamps = None
    elif case == 'too few stamps':
        (tmp_path / 't.txt').write_text('0.0\n0.1\n')
        stamps = FrameStamps.from_file(tmp_path / 't.txt')
    elif case == 'missing':
        folder = tmp_path / 'nope'
    with pytest.raises(FootageError) as error:
        open_footage(folder, stamps, '--fps HZ or --timestamps FILE')
    expected = {
        'empty': 'frames: no image files',
        'no stamps': 'is an image folder without stamps: give --fps HZ or --timestamps FILE',
        'too few stamps': 't.txt has 2 stamps but',
        'missing': 'nope: no such file or folder',
    }[case]
    assert expected in str(error.value)
