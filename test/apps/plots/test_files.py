import matplotlib

matplotlib.use('Agg')

import matplotlib.pyplot as plt  # noqa: E402
import pytest  # noqa: E402

from lumpbeam_ros.apps.plots.files import save_figure  # noqa: E402
from lumpbeam_ros.base.errors import LumpbeamError  # noqa: E402


def test_the_folder_is_created_and_the_image_written(tmp_path):
    figure, axes = plt.subplots()
    axes.plot([0, 1], [1, 0])
    try:
        path = save_figure(figure, str(tmp_path / 'a' / 'b' / 'plot.png'), dpi=50)
    finally:
        plt.close(figure)
    assert path == tmp_path / 'a' / 'b' / 'plot.png'
    assert path.read_bytes().startswith(b'\x89PNG')


def test_an_unwritable_path_is_one_line_naming_it(tmp_path):
    (tmp_path / 'file').write_text('x')
    figure = plt.figure()
    try:
        with pytest.raises(LumpbeamError) as caught:
            save_figure(figure, tmp_path / 'file' / 'plot.png', dpi=50, what='the plot ')
    finally:
        plt.close(figure)
    message = str(caught.value)
    assert message.startswith(f'cannot write the plot {tmp_path / "file" / "plot.png"}: ')
    assert '\n' not in message
