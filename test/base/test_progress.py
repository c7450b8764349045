import io

import pytest

from lumpbeam_ros.base.progress import LONG_JOB_UNITS, Progress


class _Terminal(io.StringIO):
    def isatty(self):
        return True


@pytest.mark.parametrize(
    ('total', 'stream', 'enabled', 'shown'),
    [
        (10, io.StringIO, None, False),  # a short job off a terminal: silent
        (300_000, io.StringIO, None, True),  # analyze's long job: drawn into a log too
        (10, _Terminal, None, True),
        (10, _Terminal, False, False),  # --quiet
    ],
)
def test_progress_bar_only_for_a_tty_or_a_long_job(total, stream, enabled, shown):
    stream = stream()
    bar = Progress(total, 'reading', stream=stream, width=10, enabled=enabled,
                   long_job=LONG_JOB_UNITS)  # fmt: skip
    for _ in range(total // 2):
        bar.tick()
    bar.close()
    text = stream.getvalue()
    assert bool(text) == shown
    if shown:
        assert text.endswith(' 50%\n') and '#####.....' in text
