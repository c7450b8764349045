"""The shapers' names and the workspace default: one home the command line reads cheaply."""

import subprocess
import sys


def test_the_module_imports_nothing_heavy():
    code = "import sys; import lumpbeam_ros.core.shaping.choices; print('numpy' in sys.modules)"
    out = subprocess.run([sys.executable, '-c', code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == 'False'
