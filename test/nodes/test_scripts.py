"""The console scripts: a signal that comes while a script still imports its modules.

Each script is started as the installed one starts it (``from MODULE import FUNCTION``,
read from ``setup.py``), with ``-X importtime`` so the test sees the imports go by on
stderr: the signal is sent once numpy is loaded, while rclpy, scipy and the node's own
modules are still to come.
"""

from __future__ import annotations

import re
import signal
import subprocess
import sys
import threading
from pathlib import Path

import pytest
from harness import ros_env, stop_with

ROOT = Path(__file__).resolve().parents[2]


def console_scripts() -> dict[str, str]:
    """``name -> 'module:function'`` of setup.py's console scripts."""
    text = (ROOT / 'setup.py').read_text()
    return dict(re.findall(r"'(\w+) = ([\w.]+:\w+)'", text))


def _ignore_sigint() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)


def start_importing(script: str, env: dict[str, str], *argv: str, ignore_sigint: bool = False):
    """Starts a console script; returns it once its imports are under way (numpy loaded)."""
    module, function = console_scripts()[script].split(':')
    code = f'import sys; from {module} import {function}; sys.exit({function}())'
    process = subprocess.Popen(
        [sys.executable, '-X', 'importtime', '-c', code, *argv],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        # A background job of a shell script starts with SIGINT ignored.
        preexec_fn=_ignore_sigint if ignore_sigint else None,
    )
    assert process.stderr is not None
    # Against a hang of the test itself: the script is killed if numpy never shows.
    timer = threading.Timer(60.0, process.kill)
    timer.start()
    try:
        for line in process.stderr:
            if line.rsplit('|', 1)[-1].strip() == 'numpy':
                return process
    finally:
        timer.cancel()
    pytest.fail(f'{script} ended before importing numpy: exit {process.wait()}')


def test_every_node_has_a_console_script():
    scripts = console_scripts()
    for node in ('camera', 'identifier', 'simulator', 'diagnosis', 'shaper'):
        assert f'{node}_node' in scripts


@pytest.mark.parametrize('sig', [signal.SIGINT, signal.SIGTERM], ids=lambda s: s.name)
def test_a_signal_during_the_imports_stops_a_node_quietly(ros_domain_id, tmp_path, sig):
    """The identifier under a script (SIGINT ignored at start): the signal is not lost."""
    env = ros_env(ros_domain_id, tmp_path)
    process = start_importing(
        'identifier_node', env, '--ros-args', '-p', 'use_sim_time:=true', ignore_sigint=True
    )
    code, _, stderr = stop_with(process, sig)
    assert code == 0, stderr
    assert 'Traceback' not in stderr
