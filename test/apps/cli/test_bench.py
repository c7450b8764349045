"""``lumpbeam bench`` finds the lab in the checkout, and says where it lives from a wheel."""

import subprocess
import sys
from pathlib import Path

from lumpbeam_ros.apps.cli.bench import lab_runner

ROOT = Path(__file__).resolve().parents[3]


def test_the_lab_is_found_in_the_checkout():
    assert lab_runner(ROOT).__name__ == 'lumpbeam_lab.bench.runner'


def test_without_the_lab_it_says_where_the_benchmarks_live(tmp_path):
    # A fresh interpreter in a folder with no lab, as an installed wheel runs.
    code = (
        'import sys; from pathlib import Path\n'
        'from lumpbeam_ros.apps.cli.bench import lab_runner\n'
        'from lumpbeam_ros.base.errors import LumpbeamError\n'
        'try:\n    lab_runner(Path(sys.argv[1]))\n'
        'except LumpbeamError as exc:\n    print(exc)\n'
    )
    done = subprocess.run(
        [sys.executable, '-c', code, str(tmp_path)],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        check=True,
    )
    assert 'the benchmarks are not installed with the package' in done.stdout
    assert 'lumpbeam_lab/' in done.stdout and '\n' not in done.stdout.strip()
